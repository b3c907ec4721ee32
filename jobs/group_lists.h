#pragma once
// After grouping: each group's (bin, particle) entries in bin order, so deformation can walk a cylinder's
// cross-sections top to bottom. A stable counting sort by group over the bin table, O(entries), in
// chunks of consecutive bins: count per chunk, offsets once, scatter per chunk, with cursors laid out
// group-major, chunk-minor so the lists are the same whatever runs where. Groups keep no particle lists
// of their own (seed 000 §2.2): these lists are rebuilt every frame.
#include <cstdint>
#include <span>

#include "jobs/bin_sort.h"

namespace rivulet {

// Per chunk of bins [first_bin, end_bin): counts[g] = the chunk's entries in group g (`groups` slots).
// Returns the chunk's isolated entries.
std::uint32_t count_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                                  std::span<const std::int32_t> entry_group, std::span<std::uint32_t> counts);

// Once: per-chunk counts (chunk-major: counts[c * groups + g]) to per-chunk cursors (same layout) and the
// lists' offsets (groups + 1).
void group_list_offsets(std::uint32_t groups, std::uint32_t chunks, std::span<const std::uint32_t> counts,
                        std::span<std::uint32_t> cursors, std::span<std::uint32_t> offsets);

struct GroupListsOut {
    std::span<std::uint32_t> bin;       // per list slot: its bin (= cylinder ring)
    std::span<std::uint32_t> particle;  // per list slot: particle index
    std::span<std::uint8_t> grouped;    // per particle: set to 1 when any of its entries joined a group
};

// Per chunk: writes the chunk's grouped entries at its cursors (`groups` slots, advanced in place). A
// particle's entries can fall in two chunks, so `grouped` is set with relaxed atomic stores; the caller
// clears it before.
void scatter_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                           std::span<const std::int32_t> entry_group, std::span<std::uint32_t> cursors,
                           const GroupListsOut& out);

}  // namespace rivulet
