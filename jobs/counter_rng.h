#pragma once
// Counter-based random numbers: a value is a pure function of (seed, frame, particle id, stream), so
// emission gives the same particles whatever thread or order produces them.
#include <cstdint>

namespace rivulet {

// SplitMix64 finaliser: a bijective 64-bit mixer with full avalanche.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

constexpr std::uint64_t counter_hash(std::uint64_t seed, std::uint64_t frame, std::uint64_t id,
                                     std::uint64_t stream) {
    return mix64(mix64(mix64(mix64(seed) ^ frame) ^ id) ^ stream);
}

// Uniform in [0, 1) with 24 bits, exactly representable as float.
constexpr float counter_uniform(std::uint64_t seed, std::uint64_t frame, std::uint64_t id,
                                std::uint64_t stream) {
    return static_cast<float>(counter_hash(seed, frame, id, stream) >> 40) * (1.0f / 16777216.0f);
}

}  // namespace rivulet
