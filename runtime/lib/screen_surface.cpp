#include "runtime/lib/screen_surface.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>

#include "jobs/chunk_prefix.h"
#include "jobs/density_splat.h"
#include "jobs/mesh_hash.h"
#include "jobs/particle_spacing.h"
#include "systems/render/renderer.h"

namespace rivulet {

ScreenSurface::ScreenSurface(const ScreenFluidSettings& settings, std::size_t max_particles,
                             float particle_radius)
    : settings_(settings), max_particles_(max_particles), radius_(particle_radius) {
    if (const std::string problem = settings.validate(); !problem.empty())
        throw std::invalid_argument(problem);
    for (Staged& s : staged_) s.reserve(max_particles);
    if (particle_radius > 0.0f) {
        spacing_heads_.reserve(cell_hash_table_size(max_particles) + 1);
        spacing_order_.reserve(std::max<std::size_t>(max_particles, 1));
        spacing_values_.reserve(kSpacingSamples);
    }
    if (!spray()) return;
    if (!(particle_radius > 0.0f))
        throw std::invalid_argument("screen-space spray needs the scene's particle radius");
    grid_.cell = settings.spray_distance * particle_radius;
    grid_.bucket_bits = SprayGrid::bits_for(max_particles);
    // The chunk size depends on the scene only, so the chunks (and the sort) are the same at any thread
    // count.
    spray_chunking_ = ParticleChunks::at_most(max_particles, kMaxSprayChunks);
    const std::size_t buckets = grid_.buckets(), n = std::max<std::size_t>(max_particles, 1);
    for (Staged& s : staged_) s.sx.reserve(n), s.sy.reserve(n), s.sz.reserve(n);
    keys_.reserve(n), neighbours_.reserve(n);
    cell_x_.reserve(n), cell_y_.reserve(n), cell_z_.reserve(n), cell_key_.reserve(n);
    bucket_counts_.reserve(buckets * kMaxSprayChunks), cursors_.reserve(buckets * kMaxSprayChunks);
    bucket_start_.reserve(buckets + 1);
}

FrameGraph::JobId ScreenSurface::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                          std::function<int()> slot, FrameGraph::JobId after) {
    const FrameGraph::JobId stage = add_position_staging(
        graph, "screen.stage", std::move(positions),
        [this, slot]() -> StagedPositions& { return staged_[slot()]; }, max_particles_, after);
    const FrameGraph::JobId spacing =
        graph.serial("screen.spacing", [this, slot] { resolve_spacing(slot()); }, {stage});
    return spray() ? add_spray_jobs(graph, slot, spacing) : spacing;
}

void ScreenSurface::resolve_spacing(int slot) {
    if (!spacing_fixed_) {
        fixed_spacing_ = measure_spacing(staged_[slot]);
        spacing_fixed_ = staged_[slot].count >= kSpacingSamples && fixed_spacing_ > 0.0f;
    }
    spacing_[slot] = fixed_spacing_;
}

float ScreenSurface::measure_spacing(const Staged& s) {
    if (!(radius_ > 0.0f) || s.count < 2) return 0.0f;
    const ConstPositions p{s.x.span(s.count), s.y.span(s.count), s.z.span(s.count)};
    const ParticleBounds b = particle_bounds(p);
    if (!b.finite) return 0.0f;
    // particle_spacing hashes cells of a quarter of `cap`: their indices must stay below 2^30.
    const float cap = 2.0f * radius_;
    for (int a = 0; a < 3; ++a)
        if (double(b.hi[a]) - double(b.lo[a]) >= 0x1p29 * (double(cap) / 4.0)) return 0.0f;
    return particle_spacing(p, b.lo, cap, kSpacingSamples,
                            {spacing_heads_.span(cell_hash_table_size(s.count) + 1),
                             spacing_order_.span(s.count), spacing_values_.span(kSpacingSamples)});
}

ScreenSurface::SprayChunk ScreenSurface::spray_chunk(const Staged& s, std::size_t c) const {
    const ParticleRange r = spray_chunking_.range(c, s.count);
    return {ConstPositions{s.x.span(s.count), s.y.span(s.count), s.z.span(s.count)}.subspan(r.begin, r.count),
            r.begin};
}

FrameGraph::JobId ScreenSurface::add_spray_jobs(FrameGraph& graph, const std::function<int()>& slot,
                                                FrameGraph::JobId after) {
    const std::size_t buckets = grid_.buckets();
    const auto chunks = [this, slot] { return spray_chunks(staged_[slot()].count); };
    const FrameGraph::JobId cells =
        graph.parallel("screen.spray_grid", chunks,
                       [this, slot, buckets](std::size_t c) {
                           const Staged& s = staged_[slot()];
                           const auto [p, at] = spray_chunk(s, c);
                           spray_grid_chunk(grid_, p, keys_.span(at + p.size()).subspan(at),
                                            bucket_counts_.span((c + 1) * buckets).subspan(c * buckets));
                       },
                       {after});
    const FrameGraph::JobId offsets =
        graph.serial("screen.spray_offsets",
                     [this, slot, buckets] {
                         const auto n = static_cast<std::uint32_t>(spray_chunks(staged_[slot()].count));
                         chunk_major_prefix(static_cast<std::uint32_t>(buckets), n, buckets,
                                            bucket_counts_.span(n * buckets), cursors_.span(n * buckets),
                                            bucket_start_.span(buckets + 1));
                     },
                     {cells});
    const FrameGraph::JobId scatter =
        graph.parallel("screen.spray_scatter", chunks,
                       [this, slot, buckets](std::size_t c) {
                           const Staged& s = staged_[slot()];
                           const auto [p, at] = spray_chunk(s, c);
                           spray_scatter_chunk(grid_, p, keys_.span(at + p.size()).subspan(at),
                                               cursors_.span((c + 1) * buckets).subspan(c * buckets),
                                               {cell_x_.span(s.count), cell_y_.span(s.count),
                                                cell_z_.span(s.count), cell_key_.span(s.count)});
                       },
                       {offsets});
    const FrameGraph::JobId count = graph.parallel(
        "screen.spray_count", chunks,
        [this, slot, buckets](std::size_t c) {
            const Staged& s = staged_[slot()];
            const auto [p, at] = spray_chunk(s, c);
            const SprayCells sorted{bucket_start_.span(buckets + 1), cell_x_.span(s.count),
                                    cell_y_.span(s.count), cell_z_.span(s.count), cell_key_.span(s.count)};
            chunk_fluid_[c] = spray_count_chunk(grid_, sorted, p, keys_.span(at + p.size()).subspan(at),
                                                static_cast<std::uint32_t>(settings_.spray_neighbours),
                                                neighbours_.span(at + p.size()).subspan(at));
        },
        {scatter});
    return graph.parallel(
        "screen.spray_split", chunks,
        [this, slot](std::size_t c) {
            Staged& s = staged_[slot()];
            const std::size_t n = spray_chunks(s.count);
            // Each chunk sums the few chunk counts it needs itself: no serial job between the passes.
            std::size_t fluid_before = 0, fluid = 0;
            for (std::size_t k = 0; k < n; ++k) (k < c ? fluid_before : fluid) += chunk_fluid_[k];
            fluid += fluid_before;
            if (c == 0) s.fluid = fluid;
            const auto [p, at] = spray_chunk(s, c);
            const SprayPositionsOut out{s.sx.span(s.count), s.sy.span(s.count), s.sz.span(s.count)};
            spray_split_chunk(p, neighbours_.span(at + p.size()).subspan(at),
                              static_cast<std::uint32_t>(settings_.spray_neighbours), fluid_before,
                              fluid + (at - fluid_before), out, out);
        },
        {count});
}

SurfaceStats ScreenSurface::stats(int slot) const {
    SurfaceStats st;
    if (spray()) st.isolated = static_cast<std::uint32_t>(staged_[slot].count - staged_[slot].fluid);
    return st;
}

std::uint64_t ScreenSurface::output_hash(int slot) const {
    const Staged& s = staged_[slot];
    const std::uint64_t spacing = std::bit_cast<std::uint32_t>(spacing_[slot]);  // it shapes the picture
    if (!spray()) {
        const std::uint64_t h[4] = {hash_bytes(s.x.data(), s.count * sizeof(float)),
                                    hash_bytes(s.y.data(), s.count * sizeof(float)),
                                    hash_bytes(s.z.data(), s.count * sizeof(float)), spacing};
        return hash_bytes(h, sizeof h);
    }
    // The water and the spray lie end to end; the boundary between them is hashed too.
    const std::uint64_t h[5] = {hash_bytes(s.sx.data(), s.count * sizeof(float)),
                                hash_bytes(s.sy.data(), s.count * sizeof(float)),
                                hash_bytes(s.sz.data(), s.count * sizeof(float)), s.fluid, spacing};
    return hash_bytes(h, sizeof h);
}

void ScreenSurface::prepare_renderer(Renderer& renderer) const {
    renderer.set_screen_fluid(settings_);
}

void ScreenSurface::fill_view(int slot, FrameView& view) const {
    const Staged& s = staged_[slot];
    view.sprite_spacing = spacing_[slot];
    if (!spray()) {
        view.sprites = {s.x.span(s.count), s.y.span(s.count), s.z.span(s.count)};
        view.spray = {};
        return;
    }
    const std::size_t f = s.fluid, k = s.count - s.fluid;
    view.sprites = {s.sx.span(f), s.sy.span(f), s.sz.span(f)};
    view.spray = {s.sx.span(s.count).subspan(f, k), s.sy.span(s.count).subspan(f, k),
                  s.sz.span(s.count).subspan(f, k)};
}

}  // namespace rivulet
