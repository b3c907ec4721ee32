#pragma once
// The particle lookup cache of one marching-slices block (seed 004 §3.2.4): the projection slice of
// (n+1)^2 columns; column (i, j) lists every particle whose R_c disc covers the column, sorted by the
// slab of its centre (mid_z, then particle index), each with min_z / max_z: the range of slices it can
// influence, all in block-local integer slice units. A corner lookup scans one column with integer
// comparisons and evaluates the kernel only for particles whose slice range holds the corner.
//
// The order of the sum is (mid_z, particle index), a global order: a corner on a block border gets the
// same bits from both blocks.
#include <algorithm>
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"

namespace rivulet {

struct ColumnEntry {
    float x, y, z;
    std::int32_t min_z, max_z, mid_z;
};

struct LookupCacheView {
    std::span<const std::uint32_t> offsets;  // (n+1)^2 + 1
    std::span<const ColumnEntry> entries;
    std::int32_t span_z = 0;  // |min_z - mid_z| and |max_z - mid_z| never exceed this
};

struct LookupScratch {
    std::span<std::uint32_t> order;   // one per block particle
    std::span<std::uint32_t> counts;  // (n + 2 reach + 4) slots: counting sort by mid_z
};

// Builds the cache of block (bi, bj, bk) from its particles (ascending index). `offsets` needs
// (n+1)^2 + 1 slots. Returns the number of entries needed; entries are written only when that fits in
// `entries` (call again with more room otherwise).
std::uint32_t build_lookup_cache(const SliceGrid& grid, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                                 ConstPositions particles, const LookupScratch& scratch,
                                 std::span<std::uint32_t> offsets, std::span<ColumnEntry> entries);

// Scratch sizes for build_lookup_cache.
inline std::size_t lookup_sort_slots(const SliceGrid& g) {
    return g.n + 2u * std::uint32_t(g.reach) + 8u;
}

// F at local corner (i, j, k) whose world position is (px, py, pz).
inline float cache_field(const LookupCacheView& c, std::uint32_t n, std::uint32_t i, std::uint32_t j,
                         std::int32_t k, float px, float py, float pz, SliceKernel f) {
    const std::uint32_t col = j * (n + 1) + i;
    const ColumnEntry* e = c.entries.data() + c.offsets[col];
    const ColumnEntry* end = c.entries.data() + c.offsets[col + 1];
    // Skip entries whose centre slab is too low to reach slice k (sorted by mid_z).
    const std::int32_t first_mid = k - c.span_z, last_mid = k + c.span_z;
    std::size_t lo = 0, hi = static_cast<std::size_t>(end - e);
    while (lo < hi) {
        const std::size_t m = (lo + hi) / 2;
        if (e[m].mid_z < first_mid)
            lo = m + 1;
        else
            hi = m;
    }
    float sum = 0.0f;
    for (e += lo; e != end && e->mid_z <= last_mid; ++e) {
        if (k < e->min_z || k > e->max_z) continue;
        const float dx = e->x - px, dy = e->y - py, dz = e->z - pz;
        sum += f(dx * dx + dy * dy + dz * dz);
    }
    return sum;
}

// Whether F >= iso at local corner (i, j, k) (world z pz): the same sum as cache_field, stopped as soon as
// it reaches iso. Exact: every term is >= 0 and float addition of a non-negative term never decreases a
// sum, so a partial sum >= iso means the whole one is too. The face scan needs only this sign, and deep
// inside the fluid a few terms settle it.
inline bool cache_inside(const LookupCacheView& c, std::uint32_t n, std::uint32_t i, std::uint32_t j,
                         std::int32_t k, float px, float py, float pz, SliceKernel f, float iso) {
    const std::uint32_t col = j * (n + 1) + i;
    const ColumnEntry* e = c.entries.data() + c.offsets[col];
    const ColumnEntry* end = c.entries.data() + c.offsets[col + 1];
    std::size_t lo = 0, hi = static_cast<std::size_t>(end - e);
    while (lo < hi) {  // the first entry whose slice range reaches k (ranges grow along the column)
        const std::size_t m = (lo + hi) / 2;
        if (e[m].max_z < k)
            lo = m + 1;
        else
            hi = m;
    }
    float sum = 0.0f;
    for (e += lo; e != end && e->min_z <= k; ++e) {
        const float dx = e->x - px, dy = e->y - py, dz = e->z - pz;
        sum += f(dx * dx + dy * dy + dz * dz);
        if (sum >= iso) return true;
    }
    return sum >= iso;
}

// F at the local corners (i, j, k) of one column for every k in [k_lo, k_hi], written to out[k - k_lo];
// pz[k - k_lo] is the world z of slice k. Bit-identical to cache_field at each corner: every corner adds
// the same terms, computed by the same float expression, in the same (entry) order; only the loops are
// swapped, so one pass over the column's entries replaces a binary search and a scan per corner.
inline void cache_column(const LookupCacheView& c, std::uint32_t n, std::uint32_t i, std::uint32_t j,
                         std::int32_t k_lo, std::int32_t k_hi, float px, float py, const float* __restrict pz,
                         SliceKernel f, float* __restrict out) {
    for (std::int32_t k = k_lo; k <= k_hi; ++k) out[k - k_lo] = 0.0f;
    const std::uint32_t col = j * (n + 1) + i;
    const ColumnEntry* e = c.entries.data() + c.offsets[col];
    const ColumnEntry* end = c.entries.data() + c.offsets[col + 1];
    // Sorted by mid_z, so min_z and max_z grow along the column: skip the entries below k_lo, stop at
    // the first above k_hi.
    std::size_t lo_e = 0, hi_e = static_cast<std::size_t>(end - e);
    while (lo_e < hi_e) {
        const std::size_t m = (lo_e + hi_e) / 2;
        if (e[m].max_z < k_lo)
            lo_e = m + 1;
        else
            hi_e = m;
    }
    for (e += lo_e; e != end && e->min_z <= k_hi; ++e) {
        const std::int32_t lo = std::max(k_lo, e->min_z), hi = std::min(k_hi, e->max_z);
        const float dx = e->x - px, dy = e->y - py;
        const float dxy = dx * dx + dy * dy;
        // Branch-free kernel (a corner beyond R_c adds +0.0f, which leaves its sum's bits unchanged):
        // the slices of one entry are independent sums, so this loop vectorises.
        for (std::int32_t k = lo; k <= hi; ++k) {
            const float dz = e->z - pz[k - k_lo];
            const float r2 = dxy + dz * dz;
            const float q = r2 * f.inv_2rc2 - 0.5f;
            const float inside = r2 < f.rc2 ? 1.0f : 0.0f;  // q * q * 1 is q * q exactly
            out[k - k_lo] += q * q * inside;
        }
    }
}

}  // namespace rivulet
