#pragma once
// The hybrid method (runtime/lib/hybrid_extractor.h) as the frame pipeline's surface: per slot, the
// streams' cylinders and spheres and the blobs' welded mesh, drawn together.
#include "runtime/lib/hybrid_extractor.h"
#include "runtime/lib/surface_system.h"

namespace rivulet {

class HybridSurface final : public SurfaceSystem {
  public:
    HybridSurface(const ScanSettings& scan, const SlicesSettings& slices, std::size_t max_particles,
                  std::size_t threads);

    SurfaceMethod method() const override { return SurfaceMethod::kHybrid; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    HybridExtractor extractor_;
    std::array<ScanOutput, kFrameSlots> cylinders_;
    std::array<SurfaceMesh, kFrameSlots> mesh_;
};

}  // namespace rivulet
