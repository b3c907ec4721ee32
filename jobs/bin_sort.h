#pragma once
// Hash-table bin sort along the V axis (Hoetzlein & Höllerer 2009 §2.1): every particle goes into
// every cross-section bin whose plane its sphere intersects, in linear time, stable (particle index
// order within a bin).
//
// Bin b is the plane y_b = top - b * spacing (bin 0 at the top, scanning downwards as the paper does).
// The sort runs in chunks of particles so the runtime can count and scatter chunks in parallel; chunk
// offsets are laid out bin-major, chunk-minor, which keeps the result identical at any thread count.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/chunk_prefix.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct BinGrid {
    float top = 0;      // y of plane 0
    float spacing = 1;  // distance between planes
    std::uint32_t bins = 0;
    float radius = 0;  // sphere radius of every particle

    float plane_y(std::uint32_t b) const { return top - static_cast<float>(b) * spacing; }
    // Planes [first, last] hit by a sphere at height y; returns false when it hits none.
    bool span_of(float y, std::uint32_t& first, std::uint32_t& last) const;
    // Upper bound of bins one sphere can span.
    std::uint32_t max_bins_per_particle() const;
};

// The result: entries[offsets[b] .. offsets[b+1]) are the particle indices in bin b, ascending; ex, ey,
// ez hold each entry's particle position in the same order, so per-bin searches read contiguous memory.
struct BinTableView {
    std::span<const std::uint32_t> offsets;  // bins + 1
    std::span<const std::uint32_t> entries;
    std::span<const float> ex, ey, ez;
    std::uint32_t bin_size(std::uint32_t b) const { return offsets[b + 1] - offsets[b]; }
    std::span<const std::uint32_t> bin(std::uint32_t b) const {
        return entries.subspan(offsets[b], offsets[b + 1] - offsets[b]);
    }
};

// Each particle's planes [first, end) (empty when it cuts none), found by pass 1 and used by pass 2.
struct ParticleBins {
    std::span<std::uint32_t> first, end;
};

// Pass 1, per chunk: counts[b] = entries chunk `y` adds to bin b (counts has grid.bins slots), and the
// chunk's particles' plane ranges.
void bin_count_chunk(const BinGrid& grid, std::span<const float> y, std::span<std::uint32_t> counts,
                     const ParticleBins& spans);

// Between the passes, once: turns per-chunk counts (chunk-major: counts[c * bins + b]) into per-chunk
// write cursors (same layout) and the bin offsets (bins + 1). Returns the total entry count.
inline std::uint32_t bin_prefix(std::uint32_t bins, std::uint32_t chunks,
                                std::span<const std::uint32_t> counts, std::span<std::uint32_t> cursors,
                                std::span<std::uint32_t> offsets) {
    return chunk_major_prefix(bins, chunks, bins, counts, cursors, offsets);
}

struct BinEntriesOut {
    std::span<std::uint32_t> entries;
    std::span<float> ex, ey, ez;
};

// Pass 2, per chunk: writes the indices (first_index + i) and positions of chunk `p` at its cursors
// (advanced in place), into the planes pass 1 found for them.
void bin_scatter_chunk(ConstPositions p, std::uint32_t first_index, const ParticleBins& spans,
                       std::span<std::uint32_t> cursors, const BinEntriesOut& out);

}  // namespace rivulet
