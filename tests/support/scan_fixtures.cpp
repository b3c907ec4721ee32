#include "support/scan_fixtures.h"

#include <algorithm>

namespace rivulet::test {

Bins bin_sort(const BinGrid& grid, const Cloud& c) {
    Bins b;
    std::vector<std::uint32_t> counts(grid.bins), cursors(grid.bins);
    b.offsets.resize(grid.bins + 1);
    bin_count_chunk(grid, c.y, counts);
    b.entries.resize(bin_prefix(grid.bins, 1, counts, cursors, b.offsets));
    bin_scatter_chunk(grid, c.y, 0, cursors, b.entries);
    return b;
}

std::vector<std::int32_t> group(const Cloud& c, const Bins& bins, float eps, std::uint32_t max_groups,
                                GroupingResult* result) {
    std::uint32_t largest = 0;
    for (std::size_t i = 0; i + 1 < bins.offsets.size(); ++i)
        largest = std::max(largest, bins.offsets[i + 1] - bins.offsets[i]);
    const std::size_t slots = grouping_hash_slots(largest);
    std::vector<std::uint32_t> blocked(max_groups), hs0(slots + 1), hs1(slots + 1), hi0(largest),
        hi1(largest);
    std::vector<std::int32_t> entry_group(bins.entries.size());
    const GroupingResult r = group_entries(c.view(), bins.view(), {eps, max_groups}, entry_group,
                                           {blocked, {hs0, hs1}, {hi0, hi1}});
    if (result) *result = r;
    return entry_group;
}

std::vector<std::int32_t> particle_groups(const Bins& bins, const std::vector<std::int32_t>& entry_group,
                                          std::size_t n) {
    std::vector<std::int32_t> g(n, kIsolated);
    for (std::size_t e = 0; e < bins.entries.size(); ++e)
        if (g[bins.entries[e]] < 0 && entry_group[e] >= 0) g[bins.entries[e]] = entry_group[e];
    return g;
}

}  // namespace rivulet::test
