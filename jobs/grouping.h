#pragma once
// Grouping of binned particles into streams (Hoetzlein & Höllerer 2009 §2.2), exactly as the paper's
// pseudocode, scanning bins top to bottom. The unit is a bin entry (a particle's circle in one
// cross-section): a particle whose sphere cuts several planes has an entry in each, and "for each pj
// in bin vi" visits entries.
//   for each entry pj of bin i, in bin order:
//     the first earlier entry pk of bin i within eps: isolated -> new group {pj, pk}; grouped -> join Gk;
//     else the first entry pk of bin i-1 within eps: isolated -> new group {pj, pk};
//                                                     Gk blocked -> pj isolated; else join Gk, block Gk;
//     else pj is isolated.
//   clear all blocks.
// Which pk is "first within eps" depends on geometry only, so it is found per bin in parallel
// (bin_neighbours.h, one link per entry). The rules are serial, but most entries do not need them: in a
// bin, the own-bin links form trees (a link points to an earlier entry), and every member of a tree ends
// in the group of its root. Only two kinds of entry can change anything: a root (it links above or to
// nothing) and the first child of a root (it starts a group when the root is isolated). So:
//   per bin, in parallel:  collect_group_events  roots, tree sizes and the bin's events in bin order
//   serial:                assign_groups         the rules over the events only (a few per stream and bin)
//   per bin, in parallel:  spread_groups         every other entry takes its root's group
// which gives the same groups as applying the rules entry by entry (tested against that).
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
    std::uint32_t isolated_entries = 0;  // entries left isolated (counted by the caller after spreading)
    std::uint32_t pool_exhausted = 0;    // entries isolated only because no cylinder was left
};

// One word per entry each: the root of the entry's tree, and at roots the tree's size.
struct LinkForest {
    std::span<std::uint32_t> root, tree_size;
};

// Per bin: fills the forest for bin b's entries and writes the bin's events (entry indices, in bin order:
// its roots and the first child of each root) at events[bins.offsets[b]...]; returns how many.
std::uint32_t collect_group_events(BinTableView bins, std::uint32_t b, std::span<const std::uint32_t> link,
                                   const LinkForest& forest, std::span<std::uint32_t> events);

struct GroupEvents {
    std::span<const std::uint32_t> events;  // as collect_group_events wrote them, one region per bin
    std::span<const std::uint32_t> count;   // per bin
};

struct GroupRanges {
    std::span<std::uint32_t> vmin, vmax;   // max_groups each: each group's first and last ring
    std::span<std::uint32_t> blocked_bin;  // max_groups slots of scratch
};

// Serial: the rules over the events. Sets entry_group of every root (and of bin i-1 entries that start
// a group), and each group's ring range. Other entries' groups are left for spread_groups.
GroupingResult assign_groups(BinTableView bins, std::span<const std::uint32_t> link, const LinkForest& forest,
                             const GroupEvents& events, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, const GroupRanges& ranges);

// Per bin, after assign_groups: every entry that is not a root takes its root's group.
void spread_groups(BinTableView bins, std::uint32_t b, const LinkForest& forest,
                   std::span<std::int32_t> entry_group);

struct GroupingScratch {
    BinHashes own_hashes, above_hashes;
    std::span<std::uint32_t> link;  // one per entry
    LinkForest forest;
    std::span<std::uint32_t> events;       // one per entry
    std::span<std::uint32_t> event_count;  // one per bin
    GroupRanges ranges;
};

// Everything on the calling thread, bin by bin, phase by phase; isolated_entries counted too.
GroupingResult group_entries(BinTableView bins, float eps, std::uint32_t max_groups,
                             std::span<std::int32_t> entry_group, const GroupingScratch& scratch,
                             std::uint32_t linear_scan_max = kDefaultLinearScanMax);

}  // namespace rivulet
