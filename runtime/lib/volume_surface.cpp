#include "runtime/lib/volume_surface.h"

#include <algorithm>
#include <stdexcept>

#include "runtime/lib/position_staging.h"
#include "runtime/lib/volume_jobs.h"
#include "systems/render/renderer.h"

namespace rivulet {

VolumeSurface::VolumeSurface(const VolumeSettings& settings, const VolumeRaycastSettings& raycast,
                             std::size_t max_particles)
    : builder_(settings, max_particles), raycast_(raycast), max_particles_(max_particles) {
    if (const std::string problem = raycast.validate(); !problem.empty())
        throw std::invalid_argument(problem);
    for (DensityVolume& v : volume_) builder_.prepare(v);
    for (StagedPositions& s : staged_) s.reserve(max_particles);
}

FrameGraph::JobId VolumeSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    const FrameGraph::JobId splat = add_volume_jobs(
        graph, builder_, positions, [this, slot]() -> DensityVolume& { return volume_[slot()]; }, {after},
        volumes_);
    return add_position_staging(
        graph, "volume.stage", positions, [this, slot]() -> StagedPositions& { return staged_[slot()]; },
        max_particles_, splat);
}

SurfaceStats VolumeSurface::stats(int slot) const {
    SurfaceStats s;
    s.groups = volume_[slot].stored;
    return s;
}

std::uint64_t VolumeSurface::output_hash(int slot) const {
    return volume_[slot].hash();
}

void VolumeSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_volume_raycast(raycast_);
}

void VolumeSurface::fill_view(int slot, FrameView& view) const {
    view.volume = volume_[slot].view();
    // The Renderer's shadow pass draws these as round points; no screen-space pass is set, so nothing else
    // draws them.
    view.sprites = staged_[slot].view();
}

}  // namespace rivulet
