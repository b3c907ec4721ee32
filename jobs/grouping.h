#pragma once
// Grouping of binned particles into streams (seed 000 §2.2), exactly as the seed's pseudocode, scanning
// bins top to bottom. The unit is a bin entry (a particle's circle in one cross-section): a particle
// whose sphere cuts several planes has an entry in each, and "for each pj in bin vi" visits entries.
//   for each entry pj of bin i, in bin order:
//     the first earlier entry pk of bin i within eps: isolated -> new group {pj, pk}; grouped -> join Gk;
//     else the first entry pk of bin i-1 within eps: isolated -> new group {pj, pk};
//                                                     Gk blocked -> pj isolated; else join Gk, block Gk;
//     else pj is isolated.
//   clear all blocks.
// Decisions where the pseudocode is silent (docs/scan_conversion.md):
//  - A group created through an isolated entry of bin i-1 is blocked in bin i as well: like a join, it
//    extends a group from the previous bin, and a second cluster must not follow it.
//  - When the cylinder pool is exhausted the entry stays isolated and the shortage is counted.
//  - A particle none of whose entries joined a group is an isolated particle (drawn as a sphere).
// "First" always means lowest position in bin order, so the result depends only on the input. Large
// bins are searched through a 2D hash of cell size eps, with the same result as a linear scan.
#include <cstdint>
#include <span>

#include "jobs/bin_sort.h"
#include "jobs/particle_spans.h"

namespace rivulet {

inline constexpr std::int32_t kIsolated = -1;

struct GroupingParams {
    float epsilon = 0.07f;
    std::uint32_t max_groups = 150;
};

// Scratch owned by the caller, sized once: blocked_bin has max_groups slots; each hash table has
// grouping_hash_slots(largest bin) start slots and room for the largest bin's items.
struct GroupingScratch {
    std::span<std::uint32_t> blocked_bin;
    std::span<std::uint32_t> hash_start[2];
    std::span<std::uint32_t> hash_items[2];
};

struct GroupingResult {
    std::uint32_t groups = 0;            // groups created: ids [0, groups)
    std::uint32_t isolated_entries = 0;  // entries left isolated
    std::uint32_t pool_exhausted = 0;    // entries isolated only because no cylinder was left
};

std::size_t grouping_hash_slots(std::uint32_t max_bin_size);

// entry_group[e] receives the group of bins.entries[e], or kIsolated.
GroupingResult group_entries(ConstPositions particles, BinTableView bins, const GroupingParams& params,
                             std::span<std::int32_t> entry_group, const GroupingScratch& scratch);

}  // namespace rivulet
