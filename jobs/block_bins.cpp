#include "jobs/block_bins.h"

#include <algorithm>

namespace rivulet {

ParticleReach particle_reach(const SliceGrid& g, float x, float y, float z) {
    ParticleReach r{};
    const float p[3] = {x, y, z}, o[3] = {g.ox, g.oy, g.oz};
    const std::uint32_t nb[3] = {g.bx, g.by, g.bz};
    const std::int32_t n = static_cast<std::int32_t>(g.n);
    for (int a = 0; a < 3; ++a) {
        const std::int32_t c = SliceGrid::cell(p[a], o[a], g.inv_voxel);
        r.lo[a] = c - g.reach;
        r.hi[a] = c + g.reach + 1;
        // Block b holds corners [b n, b n + n]: it is touched when b n <= hi and b n + n >= lo.
        const auto over = [&](std::int32_t v) {  // v / n, rounding toward zero
            return v >= 0 ? static_cast<std::int32_t>(g.block_of(static_cast<std::uint32_t>(v))) : v / n;
        };
        const std::int32_t blo = std::max<std::int32_t>(0, over(std::max(r.lo[a], 0) + n - 1) - 1);
        const std::int32_t bhi = std::min<std::int32_t>(static_cast<std::int32_t>(nb[a]) - 1, over(r.hi[a]));
        r.blo[a] = blo;
        r.bhi[a] = bhi;  // bhi < blo: no block (never for particles inside the grid)
    }
    return r;
}

std::uint32_t max_blocks_per_particle(const SliceGrid& g) {
    // A corner range [lo, lo + 2 reach + 1] touches blocks ceil(lo / n) - 1 .. floor(hi / n) (block b holds
    // corners [b n, b n + n]): at most floor((2 reach + 1) / n) + 2 per axis, when lo is a multiple of n.
    const std::uint32_t w = (2u * static_cast<std::uint32_t>(g.reach) + 1u) / g.n + 2u;
    return w * w * w;
}

namespace {
template <class Fn>
void for_blocks(const SliceGrid& g, const ParticleReach& r, Fn&& fn) {
    for (std::int32_t k = r.blo[2]; k <= r.bhi[2]; ++k)
        for (std::int32_t j = r.blo[1]; j <= r.bhi[1]; ++j)
            for (std::int32_t i = r.blo[0]; i <= r.bhi[0]; ++i)
                fn((static_cast<std::uint32_t>(k) * g.by + static_cast<std::uint32_t>(j)) * g.bx +
                   static_cast<std::uint32_t>(i));
}
}  // namespace

void block_count_chunk(const SliceGrid& g, ConstPositions p, std::span<std::uint32_t> counts) {
    std::fill(counts.begin(), counts.end(), 0u);
    for (std::size_t i = 0; i < p.size(); ++i)
        for_blocks(g, particle_reach(g, p.x[i], p.y[i], p.z[i]), [&](std::uint32_t b) { ++counts[b]; });
}

void block_scatter_chunk(const SliceGrid& g, ConstPositions p, std::uint32_t first_index,
                         std::span<std::uint32_t> cursors, const BlockEntriesOut& out) {
    for (std::uint32_t i = 0; i < p.size(); ++i)
        for_blocks(g, particle_reach(g, p.x[i], p.y[i], p.z[i]), [&](std::uint32_t b) {
            const std::uint32_t e = cursors[b]++;
            out.entries[e] = first_index + i;
            out.ex[e] = p.x[i], out.ey[e] = p.y[i], out.ez[e] = p.z[i];
        });
}

}  // namespace rivulet
