#include "runtime/lib/slices_surface.h"

#include "runtime/lib/slices_jobs.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

SlicesSurface::SlicesSurface(const SlicesSettings& settings, std::size_t max_particles, std::size_t threads)
    : extractor_(settings, max_particles) {
    extractor_.reserve_scratch(threads);
}

FrameGraph::JobId SlicesSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    return add_slices_jobs(graph, extractor_, std::move(positions),
                           [this, slot = std::move(slot)]() -> SurfaceMesh& { return mesh_[slot()]; },
                           {after})
        .stage;
}

SurfaceStats SlicesSurface::stats(int slot) const {
    return {extractor_.blocks(), 0, mesh_[slot].triangle_count(), 0};
}

std::uint64_t SlicesSurface::output_hash(int slot) const {
    return mesh_hash(mesh_[slot].view());
}

void SlicesSurface::fill_view(int slot, FrameView& view) const {
    view.mesh = mesh_[slot].view();
}

}  // namespace rivulet
