#include "jobs/sph_grid.h"

#include <algorithm>

namespace rivulet {

SphKeyRange sph_grid_count_chunk(const SphGrid& grid, std::span<const float> x, std::span<const float> y,
                                 std::span<const float> z, std::span<std::uint32_t> keys,
                                 std::span<std::uint32_t> counts) {
    if (x.empty()) return {};
    std::uint32_t lo = grid.cells(), hi = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const std::uint32_t k = grid.key(x[i], y[i], z[i]);
        keys[i] = k;
        lo = std::min(lo, k), hi = std::max(hi, k);
    }
    std::fill(counts.begin() + lo, counts.begin() + hi + 1, 0u);
    for (std::size_t i = 0; i < x.size(); ++i) ++counts[keys[i]];
    return {lo, hi + 1};
}

void sph_grid_cursors(std::uint32_t cells, std::span<const SphKeyRange> ranges, std::uint32_t cell_begin,
                      std::uint32_t cell_end, std::span<const std::uint32_t> counts,
                      std::span<std::uint32_t> cursors, std::span<std::uint32_t> totals) {
    for (std::uint32_t c = cell_begin; c < cell_end; ++c) totals[c] = 0;
    // Chunk-major rows, read contiguously, each only where its chunk has particles.
    for (std::size_t k = 0; k < ranges.size(); ++k) {
        const std::size_t row = k * cells;
        const std::uint32_t lo = std::max(cell_begin, ranges[k].begin),
                            hi = std::min(cell_end, ranges[k].end);
        for (std::uint32_t c = lo; c < hi; ++c) {
            cursors[row + c] = totals[c];
            totals[c] += counts[row + c];
        }
    }
}

std::uint32_t sph_grid_offsets(std::span<const std::uint32_t> totals, std::span<std::uint32_t> cell_start) {
    std::uint32_t running = 0;
    for (std::size_t c = 0; c < totals.size(); ++c) {
        cell_start[c] = running;
        running += totals[c];
    }
    cell_start[totals.size()] = running;
    return running;
}

void sph_grid_scatter_chunk(const SphParticlesIn& in, std::span<const std::uint32_t> keys,
                            std::span<const std::uint32_t> cell_start, std::span<std::uint32_t> cursors,
                            const SphSortedOut& out, std::size_t first) {
    const bool sources = !out.source.empty();
    for (std::size_t i = 0; i < in.size(); ++i) {
        const std::uint32_t k = keys[i];
        const std::uint32_t e = cell_start[k] + cursors[k]++;
        out.x[e] = in.x[i], out.y[e] = in.y[i], out.z[e] = in.z[i];
        out.vx[e] = in.vx[i], out.vy[e] = in.vy[i], out.vz[e] = in.vz[i];
        out.id[e] = in.id[i];
        out.key[e] = k;
        if (sources) out.source[e] = static_cast<std::uint32_t>(first + i);
    }
}

}  // namespace rivulet
