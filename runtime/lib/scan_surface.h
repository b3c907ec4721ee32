#pragma once
// Sphere scan conversion (Hoetzlein & Höllerer 2009) as the frame pipeline's surface: the jobs of scan_jobs.h
// writing a cylinder pool and isolated spheres per slot.
#include <memory>
#include "runtime/lib/surface_system.h"

#include "systems/scan/oriented_scan.h"
#include "systems/scan/scan_converter.h"
#include "systems/scan/scan_output.h"

namespace rivulet {

class ScanSurface final : public SurfaceSystem {
  public:
    ScanSurface(const ScanSettings& settings, std::size_t max_particles);

    SurfaceMethod method() const override { return SurfaceMethod::kScan; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    // One of the two, by settings.axis.
    std::unique_ptr<ScanConverter> vertical_;
    std::unique_ptr<OrientedScan> path_;
    const CylinderLayout& layout() const { return vertical_ ? vertical_->layout() : path_->layout(); }
    std::array<ScanOutput, kFrameSlots> out_;
};

}  // namespace rivulet
