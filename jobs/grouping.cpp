#include "jobs/grouping.h"

namespace rivulet {

GroupingResult assign_groups(BinTableView bins, std::span<const std::uint32_t> link, std::uint32_t max_groups,
                             std::span<std::int32_t> group, std::span<std::uint32_t> blocked_bin) {
    GroupingResult result;
    for (std::uint32_t g = 0; g < max_groups; ++g) blocked_bin[g] = kNoNeighbour;
    // "Create new group with pj and pk": pk (isolated so far) gets the new id; the group counts as
    // extended into bin b, so it is blocked there.
    auto new_group = [&](std::uint32_t pk, std::uint32_t b) -> std::int32_t {
        if (result.groups >= max_groups) {
            ++result.pool_exhausted;
            return kIsolated;
        }
        const auto g = static_cast<std::int32_t>(result.groups++);
        group[pk] = g;
        blocked_bin[g] = b;
        return g;
    };
    const auto nbins = static_cast<std::uint32_t>(bins.offsets.size() - 1);
    for (std::uint32_t b = 0; b < nbins; ++b) {
        for (std::uint32_t e = bins.offsets[b]; e < bins.offsets[b + 1]; ++e) {
            const std::uint32_t l = link[e];
            if (l == kNoNeighbour) {
                group[e] = kIsolated;
            } else if (!(l & kLinkAbove)) {
                group[e] = group[l] >= 0 ? group[l] : new_group(l, b);
            } else if (const std::uint32_t q = l & ~kLinkAbove; group[q] < 0) {
                group[e] = new_group(q, b);
            } else if (const std::int32_t gk = group[q]; blocked_bin[gk] == b) {
                group[e] = kIsolated;
            } else {
                group[e] = gk;
                blocked_bin[gk] = b;
            }
        }
    }
    for (std::int32_t g : group) result.isolated_entries += g < 0 ? 1u : 0u;
    return result;
}

GroupingResult group_entries(BinTableView bins, float eps, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, const GroupingScratch& s,
                             std::uint32_t linear_scan_max) {
    const auto nbins = static_cast<std::uint32_t>(bins.offsets.size() - 1);
    for (std::uint32_t b = 0; b < nbins; ++b)
        find_bin_neighbours(bins, b, eps, s.own_hashes, s.above_hashes, s.link, linear_scan_max);
    return assign_groups(bins, s.link, max_groups, entry_group, s.blocked_bin);
}

}  // namespace rivulet
