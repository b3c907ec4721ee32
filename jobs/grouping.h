#pragma once
// Grouping of binned particles into streams (seed 000 §2.2), exactly as the seed's pseudocode, scanning
// bins top to bottom:
//   for each new particle pj of bin i (in bin order):
//     the first visited pk of bin i within eps: isolated -> new group {pj, pk}; grouped -> join Gk;
//     else the first pk of bin i-1 within eps: isolated -> new group {pj, pk};
//                                              Gk blocked -> pj isolated; else join Gk and block Gk;
//     else pj is isolated.
//   clear all blocks.
// Decisions this implementation makes where the pseudocode is silent (docs/scan_conversion.md):
//  - A particle spans several bins; it is grouped once, in the first (top) bin it appears in.
//  - A group that already has a particle continuing into bin i is blocked in bin i before any new
//    particle is placed, so an arch cannot be wrapped down both legs whatever the order within the bin.
//  - A group created through the previous bin is blocked too (it now has a member in this bin).
//  - When the cylinder pool is exhausted the particle stays isolated and the shortage is counted.
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
    std::uint32_t groups = 0;          // groups created: ids [0, groups)
    std::uint32_t isolated = 0;        // particles left isolated (including those in no bin)
    std::uint32_t pool_exhausted = 0;  // particles isolated only because no cylinder was left
};

std::size_t grouping_hash_slots(std::uint32_t max_bin_size);

// group_of[p] receives p's group id or kIsolated.
GroupingResult group_particles(ConstPositions particles, BinTableView bins, const GroupingParams& params,
                               std::span<std::int32_t> group_of, const GroupingScratch& scratch);

}  // namespace rivulet
