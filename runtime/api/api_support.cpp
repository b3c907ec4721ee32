#include "runtime/api/api_support.h"

#include <tbb/info.h>

namespace rivulet::api {

tbb::task_arena& WorkerArena::get(int threads) {
    if (threads < 0 || threads > kMaxThreads)
        throw Error("threads must be between 0 (every hardware thread) and " + std::to_string(kMaxThreads) +
                    ", got " + std::to_string(threads));
    const int n = threads > 0 ? threads : tbb::info::default_concurrency();
    if (!arena_ || n != threads_) {
        arena_ = std::make_unique<tbb::task_arena>(n);
        threads_ = n;
    }
    return *arena_;
}

}  // namespace rivulet::api
