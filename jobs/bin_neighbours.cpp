#include "jobs/bin_neighbours.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "jobs/simd4.h"

namespace rivulet {
namespace {

struct Cell {
    std::int32_t x, z;
};

// floor(v * inv_cell) as an integer, clamped so absurd coordinates or a tiny eps cannot overflow (NaN
// clamps too). Float, not double, and a truncation instead of std::floor: SSE2 has no floor instruction.
std::int32_t cell_coord(float v, float inv_cell) {
    constexpr float kLimit = 1.0e9f;
    float s = v * inv_cell;
    s = s > kLimit ? kLimit : (s > -kLimit ? s : -kLimit);
    const auto i = static_cast<std::int32_t>(s);
    return i - static_cast<std::int32_t>(s < static_cast<float>(i));
}

Cell cell_of(float x, float z, float inv_cell) {
    return {cell_coord(x, inv_cell), cell_coord(z, inv_cell)};
}

std::uint32_t bucket_of(Cell c, std::uint32_t mask) {
    const auto h = static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.x)) * 0x9E3779B1ull ^
                   static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.z)) * 0x85EBCA77ull;
    return static_cast<std::uint32_t>(h ^ (h >> 29)) & mask;
}

// Bin b's table: start at 4 * offsets[b] + 2 * b, bit_ceil(n / 2 + 1) <= 4n + 1 buckets plus one end mark.
// A stream's bin covers few cells, so half a bucket per entry keeps collisions rare without making the
// per-bin clear and prefix passes longer than the entries themselves.
std::size_t slots_of(std::uint32_t n) {
    return std::bit_ceil(std::size_t(n) / 2u + 1u);
}
std::size_t table_base(BinTableView bins, std::uint32_t b) {
    return 4u * std::size_t(bins.offsets[b]) + 2u * b;
}

// Once a bin's long probe has failed (its hash exists), its later queries probe only this many leading
// entries before the buckets: in a bin crossed by many streams (a fountain's arcs) most queries would
// fail the long probe too.
constexpr std::uint32_t kShortProbe = 16;

struct Query {
    simd::F4 x, y, z, eps2;
    float sx, sy, sz, seps2;
    Query(float qx, float qy, float qz, float eps2_)
        : x(simd::splat(qx)),
          y(simd::splat(qy)),
          z(simd::splat(qz)),
          eps2(simd::splat(eps2_)),
          sx(qx),
          sy(qy),
          sz(qz),
          seps2(eps2_) {}
    bool near(const float* px, const float* py, const float* pz, std::uint32_t i) const {
        const float dx = px[i] - sx, dy = py[i] - sy, dz = pz[i] - sz;
        return dx * dx + dy * dy + dz * dz < seps2;
    }
};

// First of the points [0, limit) within eps of q, or limit. Four at a time; the first hit is the lowest
// set bit of the block's mask.
std::uint32_t first_near(const float* px, const float* py, const float* pz, std::uint32_t limit,
                         const Query& q) {
    std::uint32_t pos = 0;
    for (; pos + 4 <= limit; pos += 4)
        if (const unsigned hits = simd::near_mask(px + pos, py + pos, pz + pos, q.x, q.y, q.z, q.eps2))
            return pos + static_cast<std::uint32_t>(std::countr_zero(hits));
    for (; pos < limit; ++pos)
        if (q.near(px, py, pz, pos)) return pos;
    return limit;
}

void build_bin_hash(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes) {
    const std::uint32_t base = bins.offsets[b], n = bins.bin_size(b);
    const float inv_cell = 0.5f / eps;
    const std::size_t slots = slots_of(n);
    const auto mask = static_cast<std::uint32_t>(slots - 1);
    // Counts go to start[s + 2] and cursors run in start[s + 1], so after the stable scatter bucket s is
    // [start[s], start[s + 1]) without shifting the table back. The table has slots + 2 <= 4n + 2 words.
    std::uint32_t* start = hashes.start.data() + table_base(bins, b);
    for (std::size_t s = 0; s < slots + 2; ++s) start[s] = 0;
    std::uint32_t* bucket = hashes.bucket.data() + base;
    for (std::uint32_t pos = 0; pos < n; ++pos)
        bucket[pos] = bucket_of(cell_of(bins.ex[base + pos], bins.ez[base + pos], inv_cell), mask);
    for (std::uint32_t pos = 0; pos < n; ++pos) ++start[bucket[pos] + 2];
    for (std::size_t s = 2; s < slots + 2; ++s) start[s] += start[s - 1];
    for (std::uint32_t pos = 0; pos < n; ++pos) {
        const std::uint32_t k = start[bucket[pos] + 1]++;
        hashes.items[base + k] = pos;
        hashes.x[base + k] = bins.ex[base + pos];
        hashes.y[base + k] = bins.ey[base + pos];
        hashes.z[base + k] = bins.ez[base + pos];
    }
}

// A bin's hash table, built the first time a query of this job needs it.
struct LazyHash {
    const BinHashes& hashes;
    bool built = false;
};

// One bin's entries, looked up once per job rather than once per query.
struct BinEntries {
    std::uint32_t b, base, n;
    const float *ex, *ey, *ez;
    BinEntries(BinTableView bins, std::uint32_t bin)
        : b(bin),
          base(bins.offsets[bin]),
          n(bins.bin_size(bin)),
          ex(bins.ex.data() + base),
          ey(bins.ey.data() + base),
          ez(bins.ez.data() + base) {}
};

// The lowest bin position below `best` among the hits of one bucket, whose items [first, end) hold
// ascending positions: its first hit is its best, and nothing at or after `best` helps. `best` if none.
std::uint32_t first_in_bucket(const std::uint32_t* items, const float* hx, const float* hy, const float* hz,
                              std::uint32_t first, std::uint32_t end, std::uint32_t best, const Query& q) {
    std::uint32_t k = first;
    for (; k + 4 <= end && items[k] < best; k += 4)
        if (const unsigned hits = simd::near_mask(hx + k, hy + k, hz + k, q.x, q.y, q.z, q.eps2))
            return std::min(best, items[k + static_cast<std::uint32_t>(std::countr_zero(hits))]);
    for (; k < end && items[k] < best; ++k)
        if (q.near(hx, hy, hz, k)) return items[k];
    return best;
}

// First entry of the bin at a position in [probe, limit) within eps of q, through its hash table (built
// on first use); global entry index or kNoNeighbour. Out of line: a coherent stream rarely gets here.
[[gnu::noinline]] std::uint32_t first_within_hashed(BinTableView bins, const BinEntries& bin,
                                                    std::uint32_t limit, const Query& q, float eps,
                                                    float inv_cell, LazyHash& lazy) {
    if (!lazy.built) build_bin_hash(bins, bin.b, eps, lazy.hashes), lazy.built = true;
    const BinHashes& hashes = lazy.hashes;
    const std::uint32_t base = bin.base;
    const std::uint32_t* start = hashes.start.data() + table_base(bins, bin.b);
    const std::uint32_t* items = hashes.items.data() + base;
    const float* hx = hashes.x.data() + base;
    const float* hy = hashes.y.data() + base;
    const float* hz = hashes.z.data() + base;
    const auto mask = static_cast<std::uint32_t>(slots_of(bin.n) - 1);
    // Cells are 2 eps wide: an entry within eps of q lies in q's cell or a neighbour, and the eps-disc
    // spans at most two cells per axis. Clamping to the neighbours keeps that true when eps is below the
    // coordinates' float resolution.
    const Cell c = cell_of(q.sx, q.sz, inv_cell);
    Cell lo = cell_of(q.sx - eps, q.sz - eps, inv_cell), hi = cell_of(q.sx + eps, q.sz + eps, inv_cell);
    lo = {std::max(lo.x, c.x - 1), std::max(lo.z, c.z - 1)};
    hi = {std::min(hi.x, c.x + 1), std::min(hi.z, c.z + 1)};
    std::uint32_t buckets[9], count = 0;
    for (std::int32_t cz = lo.z; cz <= hi.z; ++cz) {
        for (std::int32_t cx = lo.x; cx <= hi.x; ++cx) {
            const std::uint32_t bucket = bucket_of({cx, cz}, mask);
            bool seen = false;
            for (std::uint32_t i = 0; i < count; ++i) seen |= buckets[i] == bucket;
            if (!seen) buckets[count++] = bucket;
        }
    }
    std::uint32_t best = limit;
    for (std::uint32_t i = 0; i < count; ++i)
        best = first_in_bucket(items, hx, hy, hz, start[buckets[i]], start[buckets[i] + 1], best, q);
    return best == limit ? kNoNeighbour : base + best;
}

// First entry of the bin at a position below `limit` within eps of q; global entry index or kNoNeighbour.
// In a coherent stream the answer is usually among the bin's first entries: try them in order first.
// Every path returns the same entry; the probe lengths only decide how fast.
[[gnu::always_inline]] inline std::uint32_t first_within(BinTableView bins, const BinEntries& bin,
                                                         std::uint32_t limit, const Query& q, float eps,
                                                         float inv_cell, LazyHash& lazy,
                                                         std::uint32_t linear_scan_max) {
    const std::uint32_t probe =
        std::min(limit, lazy.built ? std::min(kShortProbe, linear_scan_max) : linear_scan_max);
    if (const std::uint32_t hit = first_near(bin.ex, bin.ey, bin.ez, probe, q); hit != probe)
        return bin.base + hit;
    if (probe == limit) return kNoNeighbour;
    return first_within_hashed(bins, bin, limit, q, eps, inv_cell, lazy);
}

}  // namespace

std::size_t bin_hash_start_capacity(std::size_t entries, std::size_t bins) {
    return 4u * entries + 2u * bins;
}

void find_bin_neighbours(BinTableView bins, std::uint32_t b, float eps, const BinHashes& own,
                         const BinHashes& above, std::span<std::uint32_t> link,
                         std::uint32_t linear_scan_max) {
    const float inv_cell = 0.5f / eps, eps2 = eps * eps;
    const BinEntries own_bin(bins, b);
    const BinEntries above_bin(bins, b == 0 ? b : b - 1);
    LazyHash own_hash{own}, above_hash{above};
    for (std::uint32_t j = 0; j < own_bin.n; ++j) {
        const std::uint32_t e = own_bin.base + j;
        const Query q(bins.ex[e], bins.ey[e], bins.ez[e], eps2);
        std::uint32_t found = first_within(bins, own_bin, j, q, eps, inv_cell, own_hash, linear_scan_max);
        // The rules look above only when nothing in the own bin is near.
        if (found == kNoNeighbour && b != 0) {
            const std::uint32_t above_entry =
                first_within(bins, above_bin, above_bin.n, q, eps, inv_cell, above_hash, linear_scan_max);
            if (above_entry != kNoNeighbour) found = above_entry | kLinkAbove;
        }
        link[e] = found;
    }
}

}  // namespace rivulet
