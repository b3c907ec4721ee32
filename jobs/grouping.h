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
// Which pk is "first within eps" depends on geometry only, so it is found per bin in parallel
// (bin_neighbours.h); assign_groups() applies the rules in one serial pass.
// Decisions where the pseudocode is silent (docs/scan_conversion.md):
//  - A group created through an isolated entry of bin i-1 is blocked in bin i as well: like a join, it
//    extends a group from the previous bin, and a second cluster must not follow it.
//  - When the cylinder pool is exhausted the entry stays isolated and the shortage is counted.
//  - A particle none of whose entries joined a group is an isolated particle (drawn as a sphere).
#include <cstdint>
#include <span>

#include "jobs/bin_neighbours.h"
#include "jobs/bin_sort.h"

namespace rivulet {

inline constexpr std::int32_t kIsolated = -1;

struct GroupingResult {
    std::uint32_t groups = 0;            // groups created: ids [0, groups)
    std::uint32_t isolated_entries = 0;  // entries left isolated
    std::uint32_t pool_exhausted = 0;    // entries isolated only because no cylinder was left
};

// The serial pass over the links of find_bin_neighbours: entry_group[e] receives the group of entry e, or
// kIsolated. blocked_bin: max_groups slots of scratch.
GroupingResult assign_groups(BinTableView bins, std::span<const std::uint32_t> link, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, std::span<std::uint32_t> blocked_bin);

struct GroupingScratch {
    BinHashes own_hashes, above_hashes;
    std::span<std::uint32_t> link;         // one per entry
    std::span<std::uint32_t> blocked_bin;  // max_groups
};

// Everything on the calling thread: neighbours of every bin, then assign_groups().
GroupingResult group_entries(BinTableView bins, float eps, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, const GroupingScratch& scratch,
                             std::uint32_t linear_scan_max = kDefaultLinearScanMax);

}  // namespace rivulet
