#include "jobs/chunk_prefix.h"

namespace rivulet {

std::uint32_t chunk_major_prefix(std::uint32_t slots, std::uint32_t chunks, std::size_t row,
                                 std::span<const std::uint32_t> counts, std::span<std::uint32_t> cursors,
                                 std::span<std::uint32_t> offsets) {
    std::uint32_t running = 0;
    for (std::uint32_t s = 0; s < slots; ++s) {
        offsets[s] = running;
        for (std::uint32_t c = 0; c < chunks; ++c) {
            cursors[c * row + s] = running;
            running += counts[c * row + s];
        }
    }
    offsets[slots] = running;
    return running;
}

}  // namespace rivulet
