#pragma once
// `--threads T` bounds oneTBB and llvmpipe together (DESIGN §3.5), so 1/2/N-thread figures mean what
// they say. TBB: global_control(max_allowed_parallelism, T), which counts the calling thread.
// llvmpipe: LP_NUM_THREADS must be set before the GL context is created; T = 1 maps to 0, which
// rasterizes on the calling (render) thread instead of starting a helper thread.
#include <memory>
#include <tbb/global_control.h>

namespace rivulet {

class ThreadControl {
public:
    // threads <= 0 means "all hardware threads".
    explicit ThreadControl(int threads);
    ~ThreadControl();
    int threads() const { return threads_; }

private:
    int threads_;
    std::unique_ptr<tbb::global_control> control_;
};

// Hardware threads available to this process.
int hardware_threads();

}  // namespace rivulet
