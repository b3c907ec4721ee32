#include "runtime/lib/hybrid_surface.h"

#include "systems/render/renderer.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

HybridSurface::HybridSurface(const ScanSettings& scan, const SlicesSettings& slices,
                             std::size_t max_particles, std::size_t threads)
    : extractor_(scan, slices, max_particles) {
    extractor_.reserve_scratch(threads);
    for (ScanOutput& out : cylinders_) extractor_.prepare_output(out);
}

FrameGraph::JobId HybridSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    return extractor_.add_jobs(
        graph, std::move(positions), [this, slot]() -> ScanOutput& { return cylinders_[slot()]; },
        [this, slot]() -> SurfaceMesh& { return mesh_[slot()]; }, {after});
}

SurfaceStats HybridSurface::stats(int slot) const {
    const ScanOutput& s = cylinders_[slot];
    return {s.draw_count, s.sphere_count, s.triangles + mesh_[slot].triangle_count(), s.pool_exhausted};
}

std::uint64_t HybridSurface::output_hash(int slot) const {
    const std::uint64_t a = frame_output_hash(cylinders_[slot], extractor_.scan().layout());
    const std::uint64_t b = mesh_hash(mesh_[slot].view());
    return a ^ (b + 0x9e3779b97f4a7c15ull + (a << 6) + (a >> 2));
}

void HybridSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_cylinder_pool(extractor_.scan().layout(), extractor_.scan().settings().max_groups);
}

void HybridSurface::fill_view(int slot, FrameView& view) const {
    view.cylinders = cylinders_[slot].cylinder_view();
    view.sphere_centers = cylinders_[slot].sphere_view();
    view.mesh = mesh_[slot].view();
}

}  // namespace rivulet
