#pragma once
// `--threads T` bounds oneTBB and llvmpipe together (DESIGN §3.5), so 1/2/N-thread figures mean what
// they say. TBB: global_control(max_allowed_parallelism, T), which counts the calling thread.
// llvmpipe: LP_NUM_THREADS = T rasterizer threads (T = 1: 0, which rasterizes on the render thread itself,
// so one thread in all), set before the GL context is created. The render thread mostly waits while its
// rasterizers work, and the TBB workers extract meanwhile. Measured at T = 2 on the fountain, T
// rasterizers instead of T - 1 took the 720p frame from 45 ms to 28 ms, with extraction still hidden.
#include <tbb/global_control.h>
#include <memory>

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
