#pragma once
// Your simulation and your renderer in Rivulet's frame pipeline: while `render` draws frame N on the
// calling thread, a worker runs `step` for frame N + 1 and extracts its surface, the overlap that
// `rivulet run` uses between its renderer and its workers. Frames reach `render` in order, each once,
// with the mesh a SurfaceExtractor gives for the same particles and settings.
//
//   rivulet::SurfacePipeline pipeline(settings);
//   pipeline.run(
//       frames,
//       [&](std::uint64_t f, std::vector<float>& xyz) { my_sim.step(); my_sim.copy_positions(xyz); },
//       [&](std::uint64_t f, std::span<const float> xyz, const rivulet::MeshView& mesh) { draw(mesh); });
//
// Two frames are in flight at most: each has its own particle buffer and SurfaceExtractor (workspace),
// reused from frame to frame. Where oneTBB has a single thread (a process confined to one core), the next
// frame is stepped after the render instead: the same results, no overlap.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "rivulet/surface.h"

namespace rivulet {

class SurfacePipeline {
  public:
    // Fills `xyz` (3 floats a particle, interleaved; resize it as needed) with frame `frame`'s particles.
    // Called for frames 0, 1, ... in order, one at a time, on a worker thread (or on the calling thread
    // for frame 0 and without overlap).
    using Step = std::function<void(std::uint64_t frame, std::vector<float>& xyz)>;
    // Draws, stores or writes frame `frame`, on the thread that called run(); its particles and mesh are
    // valid until it returns.
    using Render = std::function<void(std::uint64_t frame, std::span<const float> xyz, const MeshView& mesh)>;

    explicit SurfacePipeline(const SurfaceSettings& settings);
    ~SurfacePipeline();
    SurfacePipeline(SurfacePipeline&&) noexcept;
    SurfacePipeline& operator=(SurfacePipeline&&) noexcept;

    // Runs `frames` frames and returns once the last has been rendered. An exception from `step`,
    // `render` or the extraction (rivulet::Error) stops the pipeline once the frame in flight is done and
    // leaves run() as it was thrown. run() may be called again; frame numbers restart at 0.
    void run(std::uint64_t frames, const Step& step, const Render& render);

    // false: each frame's step and extraction run on the calling thread after the previous frame's render
    // (the same results, no overlap; for comparison and debugging). Default true.
    void set_overlap(bool overlap);

  private:
    struct Slots;
    std::unique_ptr<Slots> slots_;
};

}  // namespace rivulet
