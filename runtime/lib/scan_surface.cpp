#include "runtime/lib/scan_surface.h"

#include "runtime/lib/scan_jobs.h"
#include "systems/render/renderer.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

ScanSurface::ScanSurface(const ScanSettings& settings, std::size_t max_particles) {
    if (settings.axis == CylinderAxis::kPath)
        path_ = std::make_unique<OrientedScan>(settings, max_particles);
    else
        vertical_ = std::make_unique<ScanConverter>(settings, max_particles);
    for (ScanOutput& out : out_) vertical_ ? vertical_->prepare_output(out) : path_->prepare_output(out);
}

FrameGraph::JobId ScanSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                        std::function<int()> slot, FrameGraph::JobId after) {
    auto output = [this, slot = std::move(slot)]() -> ScanOutput& { return out_[slot()]; };
    if (path_)
        return add_oriented_scan_jobs(graph, *path_, std::move(positions), std::move(output), {after}).stage;
    return add_scan_jobs(graph, *vertical_, std::move(positions), std::move(output), {after}).stage;
}

SurfaceStats ScanSurface::stats(int slot) const {
    const ScanOutput& s = out_[slot];
    return {s.draw_count, s.sphere_count, s.triangles, s.pool_exhausted};
}

std::uint64_t ScanSurface::output_hash(int slot) const {
    return frame_output_hash(out_[slot], layout());
}

void ScanSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_cylinder_pool(layout(),
                               vertical_ ? vertical_->settings().max_groups : path_->settings().max_groups);
}

void ScanSurface::fill_view(int slot, FrameView& view) const {
    view.cylinders = out_[slot].cylinder_view();
    view.sphere_centers = out_[slot].sphere_view();
}

}  // namespace rivulet
