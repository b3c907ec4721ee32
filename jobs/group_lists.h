#pragma once
// After grouping: each group's (bin, particle) entries in bin order, so one deformation job per group can
// walk its cross-sections top to bottom. A stable counting sort by group over the bin table, O(entries).
// Groups keep no particle lists of their own (seed 000 §2.2): these lists are rebuilt every frame.
#include <cstdint>
#include <span>

#include "jobs/bin_sort.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct GroupListsOut {
    std::span<std::uint32_t> offsets;     // groups + 1
    std::span<std::uint32_t> bin;         // per entry: its bin (= cylinder ring)
    std::span<std::uint32_t> particle;    // per entry: particle index
    std::span<std::uint32_t> vmin, vmax;  // per group: first and last ring
    std::span<std::uint32_t> cursor;      // scratch, groups slots
    std::span<std::uint8_t> grouped;      // per particle: 1 when any of its entries joined a group
};

// entry_group[e]: group of bins.entries[e] (grouping.h).
void build_group_lists(BinTableView bins, std::span<const std::int32_t> entry_group, std::uint32_t groups,
                       const GroupListsOut& out);

}  // namespace rivulet
