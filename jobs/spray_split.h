#pragma once
// Spray for the screen-space fluid (Green, "Screen Space Fluid Rendering for Games", GDC 2010): particles
// with few neighbours are drawn as small bright sprites instead of as part of the water's surface.
//
// Neighbours are counted with a uniform grid of cells as wide as the search distance, so a particle's
// neighbours lie in the 3x3x3 cells around its own. The grid is hashed (a fixed number of buckets) rather
// than bounded: ballistic spray flies anywhere, and a bounded grid would be sized by the farthest drop.
// The particles are sorted into buckets by the chunked counting sort of jobs/chunk_prefix.h (stable,
// identical at any thread count); every sorted entry keeps its cell key, so entries of another cell that
// share a bucket are skipped. Counts are integers and the split keeps particle order, so the output is
// the same bytes whatever order the chunks run in.
//
// The jobs, per frame, over chunks of particles (* = parallel):
//   spray_grid_chunk*  -> chunk_major_prefix -> spray_scatter_chunk* -> spray_count_chunk*
//   -> spray_split_chunk* (offsets from the chunks' fluid counts, summed by each chunk).
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"

namespace rivulet {

struct SprayGrid {
    // Cell coordinates are clamped to +-kCellLimit (21 bits each in the key): beyond a million cells from
    // the origin every particle shares the border cell, which costs time, never a wrong count.
    static constexpr std::int32_t kCellLimit = (1 << 20) - 1;

    float cell = 1;                  // the search distance, world units
    std::uint32_t bucket_bits = 10;  // 2^bucket_bits buckets

    std::uint32_t buckets() const { return std::uint32_t{1} << bucket_bits; }
    // The cell of a point packed as three biased 21-bit coordinates; NaN goes to cell 0.
    std::uint64_t key(float x, float y, float z) const;
    static std::uint64_t pack(std::int32_t ix, std::int32_t iy, std::int32_t iz) {
        return std::uint64_t(ix + kCellLimit + 1) | std::uint64_t(iy + kCellLimit + 1) << 21 |
               std::uint64_t(iz + kCellLimit + 1) << 42;
    }
    std::uint32_t bucket(std::uint64_t key) const {
        return static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ull) >> (64 - bucket_bits));
    }
    // Buckets for `max_particles`: at most four occupied cells a bucket when every particle is alone in
    // its cell; bulk fluid puts several particles in a cell (about eight at SPH spacing).
    static std::uint32_t bits_for(std::size_t max_particles);
};

// The particles sorted by bucket: entries [bucket_start[b], bucket_start[b + 1]) are bucket b's, in
// particle order, each with its position and cell key.
struct SprayCells {
    std::span<const std::uint32_t> bucket_start;  // buckets + 1
    std::span<const float> x, y, z;
    std::span<const std::uint64_t> key;
};
struct SprayCellsOut {
    std::span<float> x, y, z;
    std::span<std::uint64_t> key;
};
struct SprayPositionsOut {
    std::span<float> x, y, z;
};

// Pass 1, per chunk: keys[i] = cell of the chunk's particle i; counts[b] = its particles in bucket b
// (counts has grid.buckets() words, zeroed here).
void spray_grid_chunk(const SprayGrid& grid, ConstPositions chunk, std::span<std::uint64_t> keys,
                      std::span<std::uint32_t> counts);

// Between the passes: chunk_major_prefix(grid.buckets(), chunks, grid.buckets(), counts, cursors,
// bucket_start). Pass 2, per chunk: every particle of the chunk to its bucket's cursor (advanced in place).
void spray_scatter_chunk(const SprayGrid& grid, ConstPositions chunk, std::span<const std::uint64_t> keys,
                         std::span<std::uint32_t> cursors, const SprayCellsOut& out);

// Per chunk: counts[i] = min(the number of other particles within grid.cell of the chunk's particle i,
// cap); the search stops at the cap, so bulk fluid costs a few distance tests per particle. Returns how
// many of the chunk's particles reached the cap.
std::uint32_t spray_count_chunk(const SprayGrid& grid, const SprayCells& cells, ConstPositions chunk,
                                std::span<const std::uint64_t> keys, std::uint32_t cap,
                                std::span<std::uint32_t> counts);

// Per chunk: particles with counts[i] >= threshold go to fluid (from fluid_at), the others to spray (from
// spray_at), each in particle order. With every chunk's fluid count f_k, chunk c's fluid_at is the sum of
// f_k over k < c and its spray_at is (c * chunk size - fluid_at): the split is stable whatever the order.
void spray_split_chunk(ConstPositions chunk, std::span<const std::uint32_t> counts, std::uint32_t threshold,
                       std::size_t fluid_at, std::size_t spray_at, const SprayPositionsOut& fluid,
                       const SprayPositionsOut& spray);

}  // namespace rivulet
