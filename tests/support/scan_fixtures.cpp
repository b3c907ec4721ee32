#include "support/scan_fixtures.h"

namespace rivulet::test {

Bins bin_sort(const BinGrid& grid, const Cloud& c) {
    Bins b;
    std::vector<std::uint32_t> counts(grid.bins), cursors(grid.bins), first(c.y.size()), end(c.y.size());
    b.offsets.resize(grid.bins + 1);
    bin_count_chunk(grid, c.y, counts, {first, end});
    const std::uint32_t n = bin_prefix(grid.bins, 1, counts, cursors, b.offsets);
    b.entries.resize(n), b.ex.resize(n), b.ey.resize(n), b.ez.resize(n);
    bin_scatter_chunk(c.view(), 0, {first, end}, cursors, {b.entries, b.ex, b.ey, b.ez});
    return b;
}

std::vector<std::int32_t> group(const Cloud&, const Bins& bins, float eps, std::uint32_t max_groups,
                                GroupingResult* result, std::uint32_t linear_scan_max,
                                std::vector<std::uint32_t>* vmin_out, std::vector<std::uint32_t>* vmax_out) {
    const std::size_t n = bins.entries.size();
    const std::size_t table = bin_hash_start_capacity(n, bins.offsets.size() - 1);
    std::vector<std::uint32_t> start(table), items(n), bucket(n), start2(table), items2(n), bucket2(n),
        link(n), root(n), tree_size(n), events(n), event_count(bins.offsets.size() - 1), vmin(max_groups),
        vmax(max_groups), blocked(max_groups);
    std::vector<float> hx(n), hy(n), hz(n), hx2(n), hy2(n), hz2(n);
    std::vector<std::int32_t> entry_group(n);
    const GroupingResult r = group_entries(bins.view(), eps, max_groups, entry_group,
                                           {{start, items, hx, hy, hz, bucket},
                                            {start2, items2, hx2, hy2, hz2, bucket2},
                                            link,
                                            {root, tree_size},
                                            events,
                                            event_count,
                                            {vmin, vmax, blocked}},
                                           linear_scan_max);
    if (result) *result = r;
    if (vmin_out) *vmin_out = std::vector<std::uint32_t>(vmin.begin(), vmin.begin() + r.groups);
    if (vmax_out) *vmax_out = std::vector<std::uint32_t>(vmax.begin(), vmax.begin() + r.groups);
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
