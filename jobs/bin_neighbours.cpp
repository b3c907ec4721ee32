#include "jobs/bin_neighbours.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace rivulet {
namespace {

struct Cell {
    std::int64_t x, z;
};

// In double and clamped, so absurd coordinates or a tiny eps cannot overflow the integer cell.
std::int64_t cell_coord(float v, float inv_cell) {
    constexpr double kLimit = 4.0e18;
    return static_cast<std::int64_t>(std::clamp(std::floor(double(v) * double(inv_cell)), -kLimit, kLimit));
}

Cell cell_of(float x, float z, float inv_cell) {
    return {cell_coord(x, inv_cell), cell_coord(z, inv_cell)};
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

constexpr std::uint32_t kBlock = 8;   // candidates tested together, without an early exit
constexpr std::uint32_t kProbe = 16;  // leading entries of a large bin scanned before its buckets

struct Query {
    float x, y, z, eps, eps2;
    bool near(BinTableView bins, std::uint32_t e) const {
        const float dx = bins.ex[e] - x, dy = bins.ey[e] - y, dz = bins.ez[e] - z;
        return dx * dx + dy * dy + dz * dz < eps2;
    }
};

// First of entries [base, base + limit) within eps. Eight candidates at a time with no early exit
// inside the block, which the compiler turns into vector code; the first hit is the lowest set bit.
std::uint32_t first_linear(BinTableView bins, std::uint32_t base, std::uint32_t limit, const Query& q) {
    const float* ex = bins.ex.data() + base;
    const float* ey = bins.ey.data() + base;
    const float* ez = bins.ez.data() + base;
    std::uint32_t pos = 0;
    for (; pos + kBlock <= limit; pos += kBlock) {
        unsigned hits = 0;
        for (std::uint32_t k = 0; k < kBlock; ++k) {
            const float dx = ex[pos + k] - q.x, dy = ey[pos + k] - q.y, dz = ez[pos + k] - q.z;
            hits |= static_cast<unsigned>(dx * dx + dy * dy + dz * dz < q.eps2) << k;
        }
        if (hits) return base + pos + static_cast<std::uint32_t>(std::countr_zero(hits));
    }
    for (; pos < limit; ++pos)
        if (q.near(bins, base + pos)) return base + pos;
    return kNoNeighbour;
}

// First entry of bin b at a position below `limit` within eps of q; global entry index or kNoNeighbour.
std::uint32_t first_within(BinTableView bins, std::uint32_t b, std::uint32_t limit, const Query& q,
                           float inv_cell, const BinHashes& hashes, std::uint32_t linear_scan_max) {
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    if (n <= linear_scan_max) return first_linear(bins, base, limit, q);
    // In a coherent stream the answer is usually among the bin's first entries: try them in order first.
    const std::uint32_t probe = std::min(limit, kProbe);
    if (const std::uint32_t hit = first_linear(bins, base, probe, q); hit != kNoNeighbour) return hit;
    if (probe == limit) return kNoNeighbour;
    const std::uint32_t* start = hashes.start.data() + table_base(bins, b);
    const std::uint32_t* items = hashes.items.data() + base;
    const float* hx = hashes.x.data() + base;
    const float* hy = hashes.y.data() + base;
    const float* hz = hashes.z.data() + base;
    const auto mask = static_cast<std::uint32_t>(slots_of(n) - 1);
    // Cells are 2 eps wide: an entry within eps of q lies in q's cell or a neighbour, and the eps-disc
    // spans at most two cells per axis. Clamping to the neighbours keeps that true when eps is below the
    // coordinates' float resolution.
    const Cell c = cell_of(q.x, q.z, inv_cell);
    Cell lo = cell_of(q.x - q.eps, q.z - q.eps, inv_cell), hi = cell_of(q.x + q.eps, q.z + q.eps, inv_cell);
    lo = {std::max(lo.x, c.x - 1), std::max(lo.z, c.z - 1)};
    hi = {std::min(hi.x, c.x + 1), std::min(hi.z, c.z + 1)};
    std::uint32_t buckets[9], count = 0;
    for (std::int64_t cz = lo.z; cz <= hi.z; ++cz) {
        for (std::int64_t cx = lo.x; cx <= hi.x; ++cx) {
            const std::uint32_t bucket = bucket_of({cx, cz}, mask);
            bool seen = false;
            for (std::uint32_t i = 0; i < count; ++i) seen |= buckets[i] == bucket;
            if (!seen) buckets[count++] = bucket;
        }
    }
    std::uint32_t best = limit;
    for (std::uint32_t i = 0; i < count; ++i) {
        const std::uint32_t end = start[buckets[i] + 1];
        // Positions ascend within a bucket: its first hit is its best, and nothing at or after `best` helps.
        for (std::uint32_t k = start[buckets[i]]; k < end && items[k] < best; k += kBlock) {
            const std::uint32_t m = std::min(kBlock, end - k);
            unsigned hits = 0;
            for (std::uint32_t t = 0; t < m; ++t) {
                const float dx = hx[k + t] - q.x, dy = hy[k + t] - q.y, dz = hz[k + t] - q.z;
                hits |= static_cast<unsigned>(dx * dx + dy * dy + dz * dz < q.eps2) << t;
            }
            if (hits) {
                best = std::min(best, items[k + static_cast<std::uint32_t>(std::countr_zero(hits))]);
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

void build_bin_hash(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes,
                    std::uint32_t linear_scan_max) {
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    if (n <= linear_scan_max) return;
    const float inv_cell = 0.5f / eps;
    const std::size_t slots = slots_of(n);
    const auto mask = static_cast<std::uint32_t>(slots - 1);
    std::uint32_t* start = hashes.start.data() + table_base(bins, b);
    for (std::size_t s = 0; s <= slots; ++s) start[s] = 0;
    for (std::uint32_t pos = 0; pos < n; ++pos)
        ++start[bucket_of(cell_of(bins.ex[base + pos], bins.ez[base + pos], inv_cell), mask) + 1];
    for (std::size_t s = 0; s < slots; ++s) start[s + 1] += start[s];
    // Stable scatter with start[] as moving cursors, shifted back afterwards.
    for (std::uint32_t pos = 0; pos < n; ++pos) {
        const std::uint32_t k =
            start[bucket_of(cell_of(bins.ex[base + pos], bins.ez[base + pos], inv_cell), mask)]++;
        hashes.items[base + k] = pos;
        hashes.x[base + k] = bins.ex[base + pos];
        hashes.y[base + k] = bins.ey[base + pos];
        hashes.z[base + k] = bins.ez[base + pos];
    }
    for (std::size_t s = slots; s > 0; --s) start[s] = start[s - 1];
    start[0] = 0;
}

void find_bin_neighbours(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes,
                         std::span<std::uint32_t> first_current, std::span<std::uint32_t> first_above,
                         std::uint32_t linear_scan_max) {
    const float inv_cell = 0.5f / eps, eps2 = eps * eps;
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    for (std::uint32_t j = 0; j < n; ++j) {
        const std::uint32_t e = base + j;
        const Query q{bins.ex[e], bins.ey[e], bins.ez[e], eps, eps2};
        first_current[e] = first_within(bins, b, j, q, inv_cell, hashes, linear_scan_max);
        // The rules look above only when nothing in the own bin is near.
        const bool look_above = b > 0 && first_current[e] == kNoNeighbour;
        first_above[e] =
            look_above ? first_within(bins, b - 1, bins.bin_size(b - 1), q, inv_cell, hashes, linear_scan_max)
                       : kNoNeighbour;
    }
}

}  // namespace rivulet
