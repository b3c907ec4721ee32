#include "runtime/lib/slices_surface.h"

#include "runtime/lib/position_staging.h"
#include "runtime/lib/slices_jobs.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

SlicesSurface::SlicesSurface(const SlicesSettings& settings, std::size_t max_particles, std::size_t threads)
    : extractor_(settings, max_particles), max_particles_(max_particles) {
    extractor_.reserve_scratch(threads);
    for (Staged& s : casters_)
        s.x.reserve(max_particles), s.y.reserve(max_particles), s.z.reserve(max_particles);
}

FrameGraph::JobId SlicesSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    const FrameGraph::JobId stage =
        add_slices_jobs(graph, extractor_, positions,
                        [this, slot]() -> SurfaceMesh& { return mesh_[slot()]; }, {after})
            .stage;
    return graph.parallel(
        "slices.casters", [positions] { return staging_items(positions().size(), kStageChunk); },
        [this, positions, slot](std::size_t c) {
            Staged& s = casters_[slot()];
            const std::size_t n = stage_positions_chunk(positions(), c, kStageChunk, max_particles_,
                                                        s.x.data(), s.y.data(), s.z.data());
            if (c == 0) s.count = n;
        },
        {stage});
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
    const Staged& s = casters_[slot];
    view.sprites = {s.x.span(s.count), s.y.span(s.count), s.z.span(s.count)};
    view.mesh_casts_shadow = false;
}

}  // namespace rivulet
