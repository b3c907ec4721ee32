#include "jobs/lookup_cache.h"

#include <algorithm>

namespace rivulet {

std::uint32_t build_lookup_cache(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                                 ConstPositions p, const LookupScratch& s, std::span<std::uint32_t> offsets,
                                 std::span<ColumnEntry> entries) {
    const std::int32_t n = static_cast<std::int32_t>(g.n);
    const std::int32_t i0 = static_cast<std::int32_t>(bi) * n, j0 = static_cast<std::int32_t>(bj) * n,
                       k0 = static_cast<std::int32_t>(bk) * n;
    const std::uint32_t cols = (g.n + 1) * (g.n + 1);
    const std::uint32_t np = static_cast<std::uint32_t>(p.size());
    const SliceKernel f = SliceKernel::from_rc(g.rc);

    // Counting sort of the particles by mid_z (stable: ascending index within a slab).
    const std::int32_t mid_base = -g.reach - 2;
    const std::uint32_t slots = static_cast<std::uint32_t>(s.counts.size());
    auto mid_slot = [&](std::uint32_t q) {
        const std::int32_t mid = SliceGrid::cell(p.z[q], g.oz, g.voxel) - k0;
        return static_cast<std::uint32_t>(
            std::clamp<std::int32_t>(mid - mid_base, 0, std::int32_t(slots) - 1));
    };
    std::fill(s.counts.begin(), s.counts.end(), 0u);
    for (std::uint32_t q = 0; q < np; ++q) ++s.counts[mid_slot(q)];
    std::uint32_t run = 0;
    for (auto& c : s.counts) {
        const std::uint32_t k = c;
        c = run;
        run += k;
    }
    for (std::uint32_t q = 0; q < np; ++q) s.order[s.counts[mid_slot(q)]++] = q;

    // Two passes over (particle, covered column): count, then place.
    std::fill(offsets.begin(), offsets.begin() + cols + 1, 0u);
    auto visit = [&](auto&& emit) {
        for (std::uint32_t o = 0; o < np; ++o) {
            const std::uint32_t q = s.order[o];
            const float x = p.x[q], y = p.y[q], z = p.z[q];
            const std::int32_t cx = SliceGrid::cell(x, g.ox, g.voxel) - i0,
                               cy = SliceGrid::cell(y, g.oy, g.voxel) - j0,
                               cz = SliceGrid::cell(z, g.oz, g.voxel) - k0;
            // Columns within R_c lie in [cell(x - R_c), cell(x + R_c) + 1] (a superset: the exact test
            // below decides), narrower than the reach box that bounds z.
            const std::int32_t rlo = SliceGrid::cell(x - g.rc, g.ox, g.voxel) - i0,
                               rhi = SliceGrid::cell(x + g.rc, g.ox, g.voxel) - i0 + 1;
            const std::int32_t ilo = std::max({0, cx - g.reach, rlo}),
                               ihi = std::min({n, cx + g.reach + 1, rhi});
            const std::int32_t jlo = std::max(0, cy - g.reach), jhi = std::min(n, cy + g.reach + 1);
            const ColumnEntry entry{x, y, z, cz - g.reach, cz + g.reach + 1, cz};
            if (entry.max_z < 0 || entry.min_z > n) continue;
            for (std::int32_t j = jlo; j <= jhi; ++j) {
                const float dy = y - g.cy(j0 + j);
                if (!(dy * dy < f.rc2)) continue;  // then no dx passes either
                for (std::int32_t i = ilo; i <= ihi; ++i) {
                    const float dx = x - g.cx(i0 + i);
                    // Same float expression as the corner distance minus its z term: a superset.
                    if (!(dx * dx + dy * dy < f.rc2)) continue;
                    emit(static_cast<std::uint32_t>(j * (n + 1) + i), entry);
                }
            }
        }
    };
    visit([&](std::uint32_t col, const ColumnEntry&) { ++offsets[col + 1]; });
    for (std::uint32_t c = 0; c < cols; ++c) offsets[c + 1] += offsets[c];
    const std::uint32_t total = offsets[cols];
    if (total > entries.size()) return total;
    // Use the count slots of the sort as nothing else: write cursors walk offsets[col] upwards, then shift.
    visit([&](std::uint32_t col, const ColumnEntry& e) { entries[offsets[col]++] = e; });
    for (std::uint32_t c = cols; c > 0; --c) offsets[c] = offsets[c - 1];
    offsets[0] = 0;
    return total;
}

}  // namespace rivulet
