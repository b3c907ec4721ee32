#include "runtime/lib/thread_control.h"

#include <tbb/global_control.h>
#include <tbb/info.h>
#include <cstdlib>
#include <string>

namespace rivulet {

int hardware_threads() {
    return tbb::info::default_concurrency();
}

ThreadControl::ThreadControl(int threads) : threads_(threads > 0 ? threads : hardware_threads()) {
    control_ = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                     static_cast<std::size_t>(threads_));
    const std::string lp = std::to_string(threads_ == 1 ? 0 : threads_);
    ::setenv("LP_NUM_THREADS", lp.c_str(), 1);
}

ThreadControl::~ThreadControl() = default;

}  // namespace rivulet
