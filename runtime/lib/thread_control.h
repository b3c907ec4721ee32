#pragma once
// `--threads T` bounds oneTBB and llvmpipe together (DESIGN §3.5), so 1/2/N-thread figures mean what
// they say. TBB: global_control(max_allowed_parallelism, T), which counts the calling thread.
// llvmpipe: LP_NUM_THREADS = T - 1 rasterizer threads beside the render thread (0 rasterizes on the
// render thread itself), set before the GL context is created. While the render thread waits for its
// rasterizers the TBB workers extract, so T threads keep about T cores busy.
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
