#pragma once
// Marching slices (Janisz §3.2) as the frame pipeline's surface: the jobs of slices_jobs.h writing one
// welded triangle mesh per slot, and the particles' centres (slices.casters) that the shadow pass draws
// as round points instead of the mesh.
#include "runtime/lib/position_staging.h"
#include "runtime/lib/surface_system.h"
#include "systems/slices/slices_extractor.h"
#include "systems/slices/surface_mesh.h"

namespace rivulet {

class SlicesSurface final : public SurfaceSystem {
  public:
    // Scratch for `threads` workers is reserved here, so no frame allocates it later.
    SlicesSurface(const SlicesSettings& settings, std::size_t max_particles, std::size_t threads);

    SurfaceMethod method() const override { return SurfaceMethod::kSlices; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer&) const override {}
    void fill_view(int slot, FrameView& view) const override;

  private:
    SlicesExtractor extractor_;
    std::size_t max_particles_;
    std::array<SurfaceMesh, kFrameSlots> mesh_;
    std::array<StagedPositions, kFrameSlots> casters_;
};

}  // namespace rivulet
