#pragma once
// The prefix pass of a two-pass parallel counting sort: chunks count their items per slot (bin, group),
// then each chunk writes its items of slot s after those of the chunks before it, so every slot lists
// its items in chunk order whatever order the chunks run in.
#include <cstdint>
#include <span>

namespace rivulet {

// Per-chunk counts in chunk-major rows of `row` >= slots words (counts[c * row + s]) to per-chunk write
// cursors (same layout) and the slots' offsets (slots + 1). Returns the total item count. A row wider
// than `slots` lets each chunk's row start on its own cache line.
std::uint32_t chunk_major_prefix(std::uint32_t slots, std::uint32_t chunks, std::size_t row,
                                 std::span<const std::uint32_t> counts, std::span<std::uint32_t> cursors,
                                 std::span<std::uint32_t> offsets);

}  // namespace rivulet
