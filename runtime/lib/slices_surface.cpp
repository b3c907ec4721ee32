#include "runtime/lib/slices_surface.h"

#include "runtime/lib/position_staging.h"
#include "runtime/lib/slices_jobs.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

SlicesSurface::SlicesSurface(const SlicesSettings& settings, std::size_t max_particles, std::size_t threads)
    : extractor_(settings, max_particles), max_particles_(max_particles) {
    extractor_.reserve_scratch(threads);
    for (StagedPositions& s : casters_) s.reserve(max_particles);
}

FrameGraph::JobId SlicesSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    const FrameGraph::JobId stage =
        add_slices_jobs(graph, extractor_, positions,
                        [this, slot]() -> SurfaceMesh& { return mesh_[slot()]; }, {after})
            .stage;
    return add_position_staging(
        graph, "slices.casters", std::move(positions),
        [this, slot]() -> StagedPositions& { return casters_[slot()]; }, max_particles_, stage);
}

SurfaceStats SlicesSurface::stats(int slot) const {
    return {extractor_.blocks(), 0, mesh_[slot].triangle_count(), 0};
}

std::uint64_t SlicesSurface::output_hash(int slot) const {
    return mesh_hash(mesh_[slot].view());
}

void SlicesSurface::fill_view(int slot, FrameView& view) const {
    view.mesh = mesh_[slot].view();
    // The shadow is the particles' (round points of the particle radius, as the volume method's): no
    // screen-space pass is set, so nothing else draws them.
    view.sprites = casters_[slot].view();
    view.mesh_casts_shadow = false;
}

}  // namespace rivulet
