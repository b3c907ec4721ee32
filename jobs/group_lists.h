#pragma once
// After grouping: each group's (bin, particle) entries in bin order, so deformation can walk a cylinder's
// cross-sections top to bottom. A stable counting sort by group over the bin table, O(entries), in
// chunks of consecutive bins: count per chunk, offsets once, scatter per chunk, with cursors laid out
// group-major, chunk-minor so the lists are the same whatever runs where. Groups keep no particle lists
// of their own (Hoetzlein & Höllerer 2009 §2.2): these lists are rebuilt every frame.
#include <cstdint>
#include <span>

#include "jobs/bin_sort.h"
#include "jobs/chunk_prefix.h"

namespace rivulet {

// Per chunk of bins [first_bin, end_bin): counts[g] = the chunk's entries in group g (`groups` slots).
// Returns the chunk's isolated entries.
std::uint32_t count_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                                  std::span<const std::int32_t> entry_group, std::span<std::uint32_t> counts);

// Between the passes, once: chunk_major_prefix (chunk_prefix.h) over groups. Each chunk's job increments
// its own row of counts once per entry, so rows should start on separate cache lines: rows of a multiple
// of kGroupRowAlign words.
inline constexpr std::uint32_t kGroupRowAlign = 16;

struct GroupListsOut {
    std::span<std::uint32_t> bin;       // per list slot: its bin (= cylinder ring)
    std::span<std::uint32_t> particle;  // per list slot: particle index
};

// Per chunk: writes the chunk's grouped entries at its cursors (`groups` slots, advanced in place).
void scatter_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                           std::span<const std::int32_t> entry_group, std::span<std::uint32_t> cursors,
                           const GroupListsOut& out);

// grouped[i] = 1 for every particle in the lists, 0 for the others (isolated particles). One pass on one
// thread: a bin's particles are scattered over the particle array, so chunks of bins setting flags in
// parallel would share every cache line of it.
void mark_grouped_particles(std::span<const std::uint32_t> list_particle, std::span<std::uint8_t> grouped);

}  // namespace rivulet
