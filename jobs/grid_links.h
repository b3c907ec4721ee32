#pragma once
// Links between points that sit one per cell of a grid (the oriented scan's beads), found by sweeping
// the points in cell order: for each row of cells ahead of a point (a fixed (dz, dy) offset) a cursor
// moves monotonically through the sorted keys, so a point's candidates cost a few comparisons and no
// hashing, and each pair is tested once (the half of the stencil after the point).
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"

namespace rivulet {

// Links between points closer than a link distance, as compressed rows: point i's are
// to[first[i] .. first[i + 1]), `length` their distances.
struct LinkGraph {
    std::span<const std::uint32_t> first;  // points + 1
    std::span<const std::uint32_t> to;
    std::span<const float> length;
};

// A cell's key: 21 bits per index, z most significant, so keys sort by (z, y, x).
inline constexpr int kCellKeyBits = 21;
inline std::uint64_t pack_cell_key(std::uint64_t ix, std::uint64_t iy, std::uint64_t iz) {
    return (iz << (2 * kCellKeyBits)) | (iy << kCellKeyBits) | ix;
}

// The pairs a < b of points closer than `link`, written as far as the spans hold; returns how many there
// are (when more than fit, the caller grows the spans and calls again). `key`: the points' cells,
// strictly ascending (one point per cell); every index of a cell at least `reach` and below
// 2^21 - reach, where `reach` (1 to 3; throws std::invalid_argument otherwise) is how many cells apart two
// linked points can be. Pairs come in order of a, then of the row offset, then of b: the same every run.
std::size_t grid_link_pairs(ConstPositions p, std::span<const std::uint64_t> key, std::uint32_t reach,
                            float link, std::span<std::uint32_t> pair_a, std::span<std::uint32_t> pair_b,
                            std::span<float> pair_length);

// The pairs as rows of both ends (first: points + 1; to and length: 2 x pairs), each row in pair order.
void link_rows(std::span<const std::uint32_t> pair_a, std::span<const std::uint32_t> pair_b,
               std::span<const float> pair_length, std::span<std::uint32_t> first,
               std::span<std::uint32_t> to, std::span<float> length);

}  // namespace rivulet
