#pragma once
// What the public API's implementation shares (not installed): one way to turn the internal exceptions
// into rivulet::Error, and the task arena that bounds a call's workers.
#include <tbb/task_arena.h>
#include <memory>
#include <new>
#include <string>

#include "rivulet/error.h"

namespace rivulet::api {

// Runs f(); whatever it throws leaves as rivulet::Error with the same message.
template <class F>
decltype(auto) translate_errors(F&& f) {
    try {
        return f();
    } catch (const Error&) {
        throw;
    } catch (const std::bad_alloc&) {
        throw Error("out of memory");
    } catch (const std::exception& e) {
        throw Error(e.what());
    }
}

inline constexpr int kMaxThreads = 1024;  // as the command line's --threads

// An arena of `threads` workers (0: every hardware thread), kept while the count stays the same.
class WorkerArena {
  public:
    tbb::task_arena& get(int threads);

  private:
    int threads_ = -1;
    std::unique_ptr<tbb::task_arena> arena_;
};

}  // namespace rivulet::api
