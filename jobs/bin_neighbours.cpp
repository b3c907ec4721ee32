#include "jobs/bin_neighbours.h"

#include <bit>
#include <cmath>

namespace rivulet {
namespace {

// Below this many entries a linear scan of the bin beats building its hash.
constexpr std::uint32_t kLinearScanMax = 48;

struct Cell {
    std::int64_t x, z;
};

Cell cell_of(float x, float z, float inv_cell) {
    return {static_cast<std::int64_t>(std::floor(x * inv_cell)),
            static_cast<std::int64_t>(std::floor(z * inv_cell))};
}

std::uint32_t bucket_of(Cell c, std::uint32_t mask) {
    const auto h =
        static_cast<std::uint64_t>(c.x) * 0x9E3779B1ull ^ static_cast<std::uint64_t>(c.z) * 0x85EBCA77ull;
    return static_cast<std::uint32_t>(h ^ (h >> 29)) & mask;
}

// Bin b's table: start at 4 * offsets[b] + 2 * b, bit_ceil(2n + 1) <= 4n + 1 slots plus one end mark.
std::size_t slots_of(std::uint32_t n) {
    return std::bit_ceil(std::size_t(n) * 2u + 1u);
}
std::size_t table_base(BinTableView bins, std::uint32_t b) {
    return 4u * std::size_t(bins.offsets[b]) + 2u * b;
}

struct Query {
    float x, y, z, eps2;
    bool near(BinTableView bins, std::uint32_t e) const {
        const float dx = bins.ex[e] - x, dy = bins.ey[e] - y, dz = bins.ez[e] - z;
        return dx * dx + dy * dy + dz * dz < eps2;
    }
};

// First entry of bin b at a position below `limit` within eps of q; global entry index or kNoNeighbour.
std::uint32_t first_within(BinTableView bins, std::uint32_t b, std::uint32_t limit, const Query& q,
                           float inv_cell, const BinHashes& hashes) {
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    if (n <= kLinearScanMax) {
        for (std::uint32_t pos = 0; pos < limit; ++pos)
            if (q.near(bins, base + pos)) return base + pos;
        return kNoNeighbour;
    }
    const std::uint32_t* start = hashes.start.data() + table_base(bins, b);
    const std::uint32_t* items = hashes.items.data() + base;
    const auto mask = static_cast<std::uint32_t>(slots_of(n) - 1);
    const Cell c = cell_of(q.x, q.z, inv_cell);
    std::uint32_t best = limit;
    // Own cell first: the likeliest match, and a low `best` cuts the other buckets short.
    static constexpr int kOrder[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                         {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
    for (const auto& d : kOrder) {
        const std::uint32_t bucket = bucket_of({c.x + d[0], c.z + d[1]}, mask);
        for (std::uint32_t k = start[bucket]; k < start[bucket + 1]; ++k) {
            const std::uint32_t pos = items[k];
            if (pos >= best) break;  // items ascend: nothing better in this bucket
            if (q.near(bins, base + pos)) {
                best = pos;
                break;
            }
        }
    }
    return best == limit ? kNoNeighbour : base + best;
}

}  // namespace

std::size_t bin_hash_start_capacity(std::size_t entries, std::size_t bins) {
    return 4u * entries + 2u * bins;
}

void build_bin_hash(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes) {
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    if (n <= kLinearScanMax) return;
    const float inv_cell = 1.0f / eps;
    const std::size_t slots = slots_of(n);
    const auto mask = static_cast<std::uint32_t>(slots - 1);
    std::uint32_t* start = hashes.start.data() + table_base(bins, b);
    std::uint32_t* items = hashes.items.data() + base;
    for (std::size_t s = 0; s <= slots; ++s) start[s] = 0;
    for (std::uint32_t pos = 0; pos < n; ++pos)
        ++start[bucket_of(cell_of(bins.ex[base + pos], bins.ez[base + pos], inv_cell), mask) + 1];
    for (std::size_t s = 0; s < slots; ++s) start[s + 1] += start[s];
    // Stable scatter with start[] as moving cursors, shifted back afterwards.
    for (std::uint32_t pos = 0; pos < n; ++pos)
        items[start[bucket_of(cell_of(bins.ex[base + pos], bins.ez[base + pos], inv_cell), mask)]++] = pos;
    for (std::size_t s = slots; s > 0; --s) start[s] = start[s - 1];
    start[0] = 0;
}

void find_bin_neighbours(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes,
                         std::span<std::uint32_t> first_current, std::span<std::uint32_t> first_above) {
    const float inv_cell = 1.0f / eps, eps2 = eps * eps;
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    for (std::uint32_t j = 0; j < n; ++j) {
        const std::uint32_t e = base + j;
        const Query q{bins.ex[e], bins.ey[e], bins.ez[e], eps2};
        first_current[e] = first_within(bins, b, j, q, inv_cell, hashes);
        // The rules look above only when nothing in the own bin is near.
        const bool look_above = b > 0 && first_current[e] == kNoNeighbour;
        first_above[e] =
            look_above ? first_within(bins, b - 1, bins.bin_size(b - 1), q, inv_cell, hashes) : kNoNeighbour;
    }
}

}  // namespace rivulet
