#pragma once
// The particle lookup cache of one marching-slices block (Janisz §3.2.4): the projection slice of
// (n+1)^2 columns; column (i, j) lists every particle whose R_c disc covers the column, sorted by the
// slab of its centre (mid_z, then particle index). min_z = mid_z - reach and max_z = mid_z + reach + 1
// bound the slices it can influence, all in block-local integer slice units. The list is cut into groups
// of four mid_z values and the cache keeps where every group of every column starts, so the mid_z of
// an entry is that of its group: a lookup for slices [k_lo, k_hi] takes, by integer arithmetic on k, the
// groups whose mid_z range can reach them, and evaluates the kernel for their entries (those of a
// group's mid_z values that cannot reach add exactly +0).
//
// An entry stores dxy = dx^2 + dy^2, its squared distance to the column's axis, and z: the corner
// distance is evaluated as dx*dx + dy*dy + dz*dz = (dx*dx + dy*dy) + dz*dz left to right, so
// dxy + dz*dz is the same float, and a lookup needs one subtraction and two products per term.
//
// The order of the sum is (mid_z, particle index), a global order: a corner on a block border gets the
// same bits from both blocks.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>

#include "jobs/anisotropic_kernels.h"
#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"
#include "jobs/vector_lanes.h"

namespace rivulet {

// A particle's entry in one column; its mid_z (slab of the centre) is implied by the group it lies in.
struct ColumnEntry {
    float dxy;  // squared distance to the column's axis (x and y terms of the corner distance)
    float z;
};

// A column's entries are cut into groups of 4 consecutive mid_z values; the cache keeps where each group
// starts, so the entries that can reach a run of slices are found with two loads (no binary search,
// whose chain of dependent loads into an array the size of L2 cost more than the kernel itself). The
// groups round that range out by a few entries that lie beyond R_c of every slice of the run: they add
// exactly +0, and scanning them costs less than finding where to start and stop.
inline constexpr std::int32_t kLookupGroupShift = 2;  // groups of 4 slabs
// Group of mid_z (entries of the block have mid_z >= -reach - 1, so the group is never negative).
inline std::uint32_t lookup_group(std::int32_t mid_z, std::int32_t reach) {
    return static_cast<std::uint32_t>(mid_z + reach + 2) >> kLookupGroupShift;
}

// An anisotropic particle's entry (jobs/anisotropic_kernels.h): at corner height pz its squared
// distance in the kernel's metric is a + c (z - pz)^2, its term amp * f of that.
struct AnisoEntry {
    float a;  // the metric's distance to the column (its minimum over z)
    float z;  // the height where the column passes closest to the centre, in the metric
    float c;  // the metric's zz entry
    float amp;
};

template <class Entry>
struct BasicLookupCacheView {
    // Group g of column c starts at entry offsets[g * columns + c]; row `groups` holds the column ends.
    std::span<const std::uint32_t> offsets;
    std::span<const Entry> entries;
    std::int32_t reach = 1;  // an entry reaches slices [mid_z - reach, mid_z + reach + 1]
    std::uint32_t groups = 1, columns = 1;

    // From the start of the group holding the lowest mid_z that reaches slice k_lo >= 0 to the end of
    // the group holding the highest that reaches k_hi: every entry reaching a slice of [k_lo, k_hi].
    const Entry* group_start(std::uint32_t col, std::int32_t k_lo) const {
        const std::uint32_t g = std::min(lookup_group(k_lo - reach - 1, reach), groups);
        return entries.data() + offsets[g * columns + col];
    }
    const Entry* group_end(std::uint32_t col, std::int32_t k_hi) const {
        const std::uint32_t g = std::min(lookup_group(k_hi + reach, reach) + 1, groups);
        return entries.data() + offsets[g * columns + col];
    }
};
using LookupCacheView = BasicLookupCacheView<ColumnEntry>;
using AnisoLookupCacheView = BasicLookupCacheView<AnisoEntry>;

struct LookupScratch {
    std::span<std::uint32_t> order;   // one per block particle
    std::span<std::int32_t> mids;     // one per block particle: its mid_z
    std::span<std::uint32_t> counts;  // lookup_sort_slots: counting sort by mid_z
    std::span<std::uint16_t> rows;    // lookup_row_slots per block particle: covered columns per row
};

// Builds the cache of block (bi, bj, bk) from its particles (ascending index). `offsets` needs
// lookup_offset_slots(grid) slots. Returns the number of entries needed; entries are written only when that
// fits in `entries` (call again with more room otherwise).
std::uint32_t build_lookup_cache(const SliceGrid& grid, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                                 ConstPositions particles, const LookupScratch& scratch,
                                 std::span<std::uint32_t> offsets, std::span<ColumnEntry> entries);
// The same for anisotropic kernels: `particles` are the block's smoothed centres, ids[q] is where
// particle q's shape sits in `shapes`. A particle's columns are those its ellipsoid meets, its reach in
// z the grid's (which must cover the longest axis).
std::uint32_t build_aniso_lookup_cache(const SliceGrid& grid, std::uint32_t bi, std::uint32_t bj,
                                       std::uint32_t bk, ConstPositions particles,
                                       std::span<const std::uint32_t> ids, ConstKernelShapes shapes,
                                       const LookupScratch& scratch, std::span<std::uint32_t> offsets,
                                       std::span<AnisoEntry> entries);

// Scratch sizes for build_lookup_cache.
inline std::size_t lookup_sort_slots(const SliceGrid& g) {
    return g.n + 2u * std::uint32_t(g.reach) + 8u;
}
// Groups per column: every slot of the counting sort by mid_z falls in one.
inline std::uint32_t lookup_groups(const SliceGrid& g) {
    return static_cast<std::uint32_t>((lookup_sort_slots(g) + (1u << kLookupGroupShift) - 1) >>
                                      kLookupGroupShift);
}
inline std::size_t lookup_offset_slots(const SliceGrid& g) {
    return std::size_t(g.n + 1) * (g.n + 1) * (lookup_groups(g) + 1);
}
// Per block particle: the run of covered columns in each row of its reach box, then the box's first row.
inline std::size_t lookup_row_slots(const SliceGrid& g) {
    return 2u * std::uint32_t(g.reach) + 3u;
}

// F at local corner (i, j, k) whose world z is pz.
template <class Entry>
float cache_field(const BasicLookupCacheView<Entry>& c, std::uint32_t n, std::uint32_t i, std::uint32_t j,
                  std::int32_t k, float pz, SliceKernel f) {
    const std::uint32_t col = j * (n + 1) + i;
    float sum = 0.0f;
    for (const Entry *e = c.group_start(col, k), *end = c.group_end(col, k); e != end; ++e) {
        const float dz = e->z - pz;
        if constexpr (std::is_same_v<Entry, AnisoEntry>)
            sum += e->amp * f(e->a + e->c * (dz * dz));
        else
            sum += f(e->dxy + dz * dz);
    }
    return sum;
}

// F at the local corners (i, j, k) of one column for every k in [k_lo, k_hi], written to out[k - k_lo];
// pz[k - k_lo] is the world z of slice k, readable (any value), and out writable, up to the next multiple
// of Lanes entries: whole vectors are stored (a store of the live lanes only was compiled into a call to
// memcpy, in the hottest loop of the sweep).
// Bit-identical to cache_field at each corner: every corner adds the same terms, computed by the same
// float expressions, in the same (entry) order. Lanes slices at a time share one pass over the entries
// that reach any of them; an entry out of a slice's range is beyond R_c there and adds +0.0f, which
// leaves that sum's bits unchanged, so the lane count changes no bit either. GCC/Clang vector
// extensions: independent IEEE lanes, the same operations as the scalar code (no contraction:
// -ffp-contract=off). The seed walks, the face scans, the exhaustive seeds and the sweep all evaluate
// corners through this (a lone corner is a run of one); cache_field is the tests' scalar reference. Eight
// lanes only pay in a function built for AVX2 (march_block's).
template <int Lanes = 4, class Entry>
inline void cache_column(const BasicLookupCacheView<Entry>& c, std::uint32_t n, std::uint32_t i,
                         std::uint32_t j, std::int32_t k_lo, std::int32_t k_hi, const float* pz,
                         SliceKernel f, float* out) {
    using fv = typename VectorLanes<Lanes>::f;  // Lanes slices to a vector
    using iv = typename VectorLanes<Lanes>::i;
    const std::uint32_t col = j * (n + 1) + i;
    const fv rc2 = fv{} + f.rc2, inv = fv{} + f.inv_2rc2, half = fv{} + 0.5f;
    for (std::int32_t a = k_lo; a <= k_hi; a += Lanes) {
        const std::int32_t b = std::min(a + Lanes - 1, k_hi);
        fv z;
        std::memcpy(&z, pz + (a - k_lo), sizeof z);  // lanes past k_hi: padding, never stored
        fv sum = fv{};
        for (const Entry *e = c.group_start(col, a), *end = c.group_end(col, b); e != end; ++e) {
            const fv dz = e->z - z;
            if constexpr (std::is_same_v<Entry, AnisoEntry>) {
                const fv r2 = e->a + e->c * (dz * dz);
                const fv q = r2 * inv - half;
                const fv term = e->amp * (q * q);
                sum += reinterpret_cast<fv>(reinterpret_cast<iv>(term) & (r2 < rc2));
            } else {
                const fv r2 = e->dxy + dz * dz;
                const fv q = r2 * inv - half;
                const fv term = q * q;
                sum += reinterpret_cast<fv>(reinterpret_cast<iv>(term) & (r2 < rc2));  // +0 beyond R_c
            }
        }
        std::memcpy(out + (a - k_lo), &sum, sizeof sum);
    }
}

}  // namespace rivulet
