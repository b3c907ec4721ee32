#pragma once
// Staging a frame's particle centres into a frame slot, one item per chunk (screen.stage, volume.stage):
// the render thread draws the slot's copy while the workers move on to the next frame.
#include <algorithm>
#include <cstddef>

#include "jobs/particle_spans.h"

namespace rivulet {

// Items of a staging job of n particles in chunks of `chunk` (at least one, so an empty frame still
// records its count).
inline std::size_t staging_items(std::size_t n, std::size_t chunk) {
    return std::max<std::size_t>((n + chunk - 1) / chunk, 1);
}

// Item c: copies chunk c of the first min(p.size(), max) particles of `p` to the same places of x, y, z.
// Returns that count, the same for every item.
inline std::size_t stage_positions_chunk(ConstPositions p, std::size_t c, std::size_t chunk, std::size_t max,
                                         float* x, float* y, float* z) {
    const std::size_t n = std::min(p.size(), max);
    const std::size_t begin = std::min(c * chunk, n), end = std::min(begin + chunk, n);
    std::copy(p.x.begin() + begin, p.x.begin() + end, x + begin);
    std::copy(p.y.begin() + begin, p.y.begin() + end, y + begin);
    std::copy(p.z.begin() + begin, p.z.begin() + end, z + begin);
    return n;
}

}  // namespace rivulet
