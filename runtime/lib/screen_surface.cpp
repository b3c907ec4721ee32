#include "runtime/lib/screen_surface.h"

#include <algorithm>
#include <cstring>

#include "jobs/mesh_hash.h"
#include "systems/render/renderer.h"

namespace rivulet {

ScreenSurface::ScreenSurface(const ScreenFluidSettings& settings, std::size_t max_particles)
    : settings_(settings), max_particles_(max_particles) {
    if (const std::string problem = settings.validate(); !problem.empty())
        throw std::invalid_argument(problem);
    for (Staged& s : staged_)
        s.x.reserve(max_particles), s.y.reserve(max_particles), s.z.reserve(max_particles);
}

FrameGraph::JobId ScreenSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    return graph.parallel(
        "screen.stage",
        [positions] { return std::max<std::size_t>((positions().size() + kChunk - 1) / kChunk, 1); },
        [this, positions, slot](std::size_t c) {
            const ConstPositions p = positions();
            Staged& s = staged_[slot()];
            const std::size_t n = std::min(p.size(), max_particles_);
            if (c == 0) s.count = n;  // every item writes its own range; the count is the same for all
            const std::size_t begin = std::min(c * kChunk, n), end = std::min(begin + kChunk, n);
            std::copy(p.x.begin() + begin, p.x.begin() + end, s.x.data() + begin);
            std::copy(p.y.begin() + begin, p.y.begin() + end, s.y.data() + begin);
            std::copy(p.z.begin() + begin, p.z.begin() + end, s.z.data() + begin);
        },
        {after});
}

SurfaceStats ScreenSurface::stats(int) const {
    return {};
}

std::uint64_t ScreenSurface::output_hash(int slot) const {
    const Staged& s = staged_[slot];
    const std::uint64_t h[3] = {hash_bytes(s.x.data(), s.count * sizeof(float)),
                                hash_bytes(s.y.data(), s.count * sizeof(float)),
                                hash_bytes(s.z.data(), s.count * sizeof(float))};
    return hash_bytes(h, sizeof h);
}

void ScreenSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_screen_fluid(settings_);
}

void ScreenSurface::fill_view(int slot, FrameView& view) const {
    const Staged& s = staged_[slot];
    view.sprites = {s.x.span(s.count), s.y.span(s.count), s.z.span(s.count)};
}

}  // namespace rivulet
