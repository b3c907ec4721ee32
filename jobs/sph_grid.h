#pragma once
// Uniform-grid neighbour search for SPH: particles are sorted by cell with the chunked counting sort of
// the hash-sort job (jobs/bin_sort.h): per chunk count -> one prefix pass laid out cell-major,
// chunk-minor -> per chunk stable scatter. The result is the particles reordered by cell (ids travel with
// them) and each cell's range, identical at any thread count. Cells are h wide, so the neighbours of a
// particle within h lie in the 3x3x3 cells around its own, visited in a fixed order.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/vec3.h"

namespace rivulet {

struct SphGrid {
    Vec3f origin;  // corner of cell (0, 0, 0)
    float cell = 1;
    std::uint32_t nx = 1, ny = 1, nz = 1;

    std::uint32_t cells() const { return nx * ny * nz; }
    static std::uint32_t clamp_index(float f, std::uint32_t n) {
        // NaN and negatives go to 0; truncation is floor for f >= 0.
        if (!(f > 0.0f)) return 0;
        if (f >= static_cast<float>(n - 1)) return n - 1;
        return static_cast<std::uint32_t>(f);
    }
    // Cell of a point; points outside the grid go to the nearest border cell.
    std::uint32_t key(float x, float y, float z) const {
        const float inv = 1.0f / cell;
        const std::uint32_t ix = clamp_index((x - origin.x) * inv, nx);
        const std::uint32_t iy = clamp_index((y - origin.y) * inv, ny);
        const std::uint32_t iz = clamp_index((z - origin.z) * inv, nz);
        return (iz * ny + iy) * nx + ix;
    }
};

// Read-only particle columns (a chunk or all of them).
struct SphParticlesIn {
    std::span<const float> x, y, z, vx, vy, vz;
    std::span<const std::uint32_t> id;
    std::size_t size() const { return x.size(); }
};

// Sorted copies: particle k of cell c sits at cell_start[c] + k.
struct SphSortedOut {
    std::span<float> x, y, z, vx, vy, vz;
    std::span<std::uint32_t> id, key;
    std::span<std::uint32_t> source = {};  // optional: index the particle had before the sort
};

// The cells [begin, end) a chunk's particles lie in (empty: begin == end).
struct SphKeyRange {
    std::uint32_t begin = 0, end = 0;
};

// Pass 1, per chunk: keys[i] = cell of particle i of the chunk; counts[c] = particles of the chunk in cell
// c for c in the returned range, the only part of `counts` written. Particles sorted by cell one substep
// earlier keep a chunk within a few thousand cells, where the whole grid has chunks x cells counters.
SphKeyRange sph_grid_count_chunk(const SphGrid& grid, std::span<const float> x, std::span<const float> y,
                                 std::span<const float> z, std::span<std::uint32_t> keys,
                                 std::span<std::uint32_t> counts);

// Between the passes, in two steps so the work over chunks x cells runs in parallel:
// 1. per range of cells [cell_begin, cell_end) (any split of the cells): from the per-chunk counts
//    (chunk-major: counts[k * cells + c], read only inside chunk k's range) each chunk's write cursor
//    relative to the cell's start (same layout, written only inside that range) and each cell's total;
// 2. once: totals -> cell_start (cells + 1, an exclusive prefix sum). Returns the particle count.
// Cell c then holds chunk 0's particles of c, then chunk 1's, ...: stable, whatever the split.
void sph_grid_cursors(std::uint32_t cells, std::span<const SphKeyRange> ranges, std::uint32_t cell_begin,
                      std::uint32_t cell_end, std::span<const std::uint32_t> counts,
                      std::span<std::uint32_t> cursors, std::span<std::uint32_t> totals);
std::uint32_t sph_grid_offsets(std::span<const std::uint32_t> totals, std::span<std::uint32_t> cell_start);

// Pass 2, per chunk: copies every particle of the chunk to cell_start[key] + its cursor (advanced in
// place), with its key (and, when out.source is given, first + its index in the chunk).
void sph_grid_scatter_chunk(const SphParticlesIn& chunk, std::span<const std::uint32_t> keys,
                            std::span<const std::uint32_t> cell_start, std::span<std::uint32_t> cursors,
                            const SphSortedOut& out, std::size_t first = 0);

// Calls f(begin, end) for each of the 9 x-rows of cells around cell `key` (itself included): the sorted
// particles [begin, end) of three cells adjacent in sorted order, in a fixed order (z, then y).
template <class F>
inline void sph_for_each_near_row(const SphGrid& g, std::span<const std::uint32_t> cell_start,
                                  std::uint32_t key, F&& f) {
    const std::uint32_t ix = key % g.nx;
    const std::uint32_t iy = (key / g.nx) % g.ny;
    const std::uint32_t iz = key / (g.nx * g.ny);
    const std::uint32_t x0 = ix > 0 ? ix - 1 : 0, x1 = ix + 1 < g.nx ? ix + 1 : ix;
    const std::uint32_t y0 = iy > 0 ? iy - 1 : 0, y1 = iy + 1 < g.ny ? iy + 1 : iy;
    const std::uint32_t z0 = iz > 0 ? iz - 1 : 0, z1 = iz + 1 < g.nz ? iz + 1 : iz;
    for (std::uint32_t cz = z0; cz <= z1; ++cz) {
        for (std::uint32_t cy = y0; cy <= y1; ++cy) {
            const std::uint32_t row = (cz * g.ny + cy) * g.nx;
            f(cell_start[row + x0], cell_start[row + x1 + 1]);
        }
    }
}

// Calls f(j) for every sorted particle j in the 27 cells around cell `key` (itself included), in the
// fixed order of sph_for_each_near_row.
template <class F>
inline void sph_for_each_near(const SphGrid& g, std::span<const std::uint32_t> cell_start, std::uint32_t key,
                              F&& f) {
    sph_for_each_near_row(g, cell_start, key, [&f](std::uint32_t begin, std::uint32_t end) {
        for (std::uint32_t j = begin; j < end; ++j) f(j);
    });
}

}  // namespace rivulet
