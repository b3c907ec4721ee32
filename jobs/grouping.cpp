#include "jobs/grouping.h"

namespace rivulet {
namespace {

bool is_root(std::uint32_t link) {
    return link == kNoNeighbour || (link & kLinkAbove) != 0;
}

}  // namespace

std::uint32_t collect_group_events(BinTableView bins, std::uint32_t b, std::span<const std::uint32_t> link,
                                   const LinkForest& forest, std::span<std::uint32_t> events) {
    const std::uint32_t base = bins.offsets[b];
    std::uint32_t count = 0;
    for (std::uint32_t e = base; e < bins.offsets[b + 1]; ++e) {
        if (is_root(link[e])) {
            forest.root[e] = e;
            forest.tree_size[e] = 1;
            events[base + count++] = e;
            continue;
        }
        const std::uint32_t r = forest.root[link[e]];
        forest.root[e] = r;
        if (forest.tree_size[r]++ == 1) events[base + count++] = e;  // the root's first child
    }
    return count;
}

GroupingResult assign_groups(BinTableView bins, std::span<const std::uint32_t> link, const LinkForest& forest,
                             const GroupEvents& ev, std::uint32_t max_groups, std::span<std::int32_t> group,
                             const GroupRanges& ranges) {
    GroupingResult result;
    for (std::uint32_t g = 0; g < max_groups; ++g) ranges.blocked_bin[g] = kNoNeighbour;
    // "Create new group with pj and pk": pk (isolated so far, in bin `first_ring`) gets the new id; the
    // group counts as extended into bin b, so it is blocked there.
    auto new_group = [&](std::uint32_t pk, std::uint32_t first_ring, std::uint32_t b) -> std::int32_t {
        if (result.groups >= max_groups) {
            ++result.pool_exhausted;
            return kIsolated;
        }
        const auto g = static_cast<std::int32_t>(result.groups++);
        group[pk] = g;
        ranges.blocked_bin[g] = b;
        ranges.vmin[g] = first_ring;
        ranges.vmax[g] = b;
        return g;
    };
    const auto nbins = static_cast<std::uint32_t>(bins.offsets.size() - 1);
    for (std::uint32_t b = 0; b < nbins; ++b) {
        const std::uint32_t base = bins.offsets[b];
        for (std::uint32_t i = 0; i < ev.count[b]; ++i) {
            const std::uint32_t e = ev.events[base + i], l = link[e];
            if (!is_root(l)) {
                // First child of an isolated root: "pk isolated -> new group {pj, pk}". When the pool is
                // out, every other member of the tree fails the same way.
                const std::uint32_t r = forest.root[e];
                if (group[r] < 0 && new_group(r, b, b) < 0) result.pool_exhausted += forest.tree_size[r] - 2;
                continue;
            }
            if (l == kNoNeighbour) {
                group[e] = kIsolated;
                continue;
            }
            // Every member of a finished bin's tree has its root's group.
            const std::uint32_t q = l & ~kLinkAbove;
            const std::int32_t gk = group[forest.root[q]];
            if (gk < 0) {
                group[e] = new_group(q, b - 1, b);
            } else if (ranges.blocked_bin[gk] == b) {
                group[e] = kIsolated;
            } else {
                group[e] = gk;
                ranges.blocked_bin[gk] = b;
                ranges.vmax[gk] = b;
            }
        }
    }
    return result;
}

void spread_groups(BinTableView bins, std::uint32_t b, const LinkForest& forest,
                   std::span<std::int32_t> entry_group) {
    for (std::uint32_t e = bins.offsets[b]; e < bins.offsets[b + 1]; ++e)
        if (const std::uint32_t r = forest.root[e]; r != e) entry_group[e] = entry_group[r];
}

GroupingResult group_entries(BinTableView bins, float eps, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, const GroupingScratch& s,
                             std::uint32_t linear_scan_max) {
    const auto nbins = static_cast<std::uint32_t>(bins.offsets.size() - 1);
    for (std::uint32_t b = 0; b < nbins; ++b) {
        find_bin_neighbours(bins, b, eps, s.own_hashes, s.above_hashes, s.link, linear_scan_max);
        s.event_count[b] = collect_group_events(bins, b, s.link, s.forest, s.events);
    }
    GroupingResult r =
        assign_groups(bins, s.link, s.forest, {s.events, s.event_count}, max_groups, entry_group, s.ranges);
    for (std::uint32_t b = 0; b < nbins; ++b) spread_groups(bins, b, s.forest, entry_group);
    for (std::int32_t g : entry_group) r.isolated_entries += g < 0 ? 1u : 0u;
    return r;
}

}  // namespace rivulet
