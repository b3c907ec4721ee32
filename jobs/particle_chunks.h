#pragma once
// How parallel jobs cut a frame's particles: consecutive index ranges of `size` particles, the last one
// shorter. A cut depends on particle counts only, never on the thread count, so per-chunk partial results
// (counts, bounds, prefix sums) combine in the same order, to the same bytes, at any thread count.
#include <algorithm>
#include <cstddef>

namespace rivulet {

// Particles per chunk unless a system asks otherwise: enough work per task that scheduling costs little.
inline constexpr std::size_t kParticleChunk = 4096;

struct ParticleRange {
    std::size_t begin = 0, count = 0;
    std::size_t end() const { return begin + count; }
};

struct ParticleChunks {
    std::size_t size = kParticleChunk;

    // One chunk size for up to max_particles in at most max_chunks chunks, none smaller than min_size
    // (fixed-size per-chunk tables hold max_chunks entries).
    static constexpr ParticleChunks at_most(std::size_t max_particles, std::size_t max_chunks,
                                            std::size_t min_size = kParticleChunk) {
        return {std::max(min_size, (max_particles + max_chunks - 1) / max_chunks)};
    }
    // Chunks for `particles` (0 for none).
    constexpr std::size_t count(std::size_t particles) const { return (particles + size - 1) / size; }
    // Chunk `chunk` of `particles`: empty past the end.
    constexpr ParticleRange range(std::size_t chunk, std::size_t particles) const {
        const std::size_t begin = std::min(chunk * size, particles);
        return {begin, std::min(size, particles - begin)};
    }
};

}  // namespace rivulet
