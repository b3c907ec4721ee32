#pragma once
// Staging a frame's particle centres into a frame slot, one item per chunk (screen.stage, volume.stage,
// slices.casters): the render thread draws the slot's copy while the workers move on to the next frame.
#include <algorithm>
#include <cstddef>
#include <functional>
#include <string>

#include "jobs/particle_spans.h"
#include "runtime/lib/frame_graph.h"
#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"

namespace rivulet {

inline constexpr std::size_t kStagingChunk = 16384;  // particles per staging item

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

// One slot's copy of the centres, reserved once for the scene's most particles.
struct StagedPositions {
    AlignedArray<float> x, y, z;
    std::size_t count = 0;
    void reserve(std::size_t n) { x.reserve(n), y.reserve(n), z.reserve(n); }
    ParticleSpritesView view() const { return {x.span(count), y.span(count), z.span(count)}; }
};

// The parallel job `name` that copies the first `max` of the frame's centres into target(), after `after`.
inline FrameGraph::JobId add_position_staging(FrameGraph& graph, std::string name,
                                              std::function<ConstPositions()> positions,
                                              std::function<StagedPositions&()> target, std::size_t max,
                                              FrameGraph::JobId after) {
    return graph.parallel(
        std::move(name), [positions] { return staging_items(positions().size(), kStagingChunk); },
        [positions, target, max](std::size_t c) {
            StagedPositions& s = target();
            const std::size_t n =
                stage_positions_chunk(positions(), c, kStagingChunk, max, s.x.data(), s.y.data(), s.z.data());
            if (c == 0) s.count = n;
        },
        {after});
}

}  // namespace rivulet
