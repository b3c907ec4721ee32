#pragma once
// Screen-space fluid (seed 004 §3.1) as the frame pipeline's surface: the workers stage the frame's
// particle positions into the slot (screen.stage, per chunk); the render thread draws them with the
// Renderer's screen-space fluid pass. No mesh is made.
#include "runtime/lib/surface_system.h"
#include "systems/particles/aligned_array.h"
#include "systems/render/screen_fluid.h"

namespace rivulet {

class ScreenSurface final : public SurfaceSystem {
  public:
    static constexpr std::size_t kChunk = 16384;  // particles per staging item

    ScreenSurface(const ScreenFluidSettings& settings, std::size_t max_particles);

    SurfaceMethod method() const override { return SurfaceMethod::kScreen; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    struct Staged {
        AlignedArray<float> x, y, z;
        std::size_t count = 0;
    };
    ScreenFluidSettings settings_;
    std::size_t max_particles_;
    std::array<Staged, kFrameSlots> staged_;
};

}  // namespace rivulet
