#pragma once
// Plain views of structure-of-arrays particle storage: what every job takes in and writes out.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rivulet {

struct ConstPositions {
    std::span<const float> x, y, z;
    std::size_t size() const { return x.size(); }
    ConstPositions subspan(std::size_t begin, std::size_t count) const {
        return {x.subspan(begin, count), y.subspan(begin, count), z.subspan(begin, count)};
    }
};

// Each particle's volume V_j = mass / density_j, where a simulation gives them (SPH); no densities: the
// consumer's own (e.g. from the particle radius). Densities are per particle, in the positions' order.
struct ParticleVolumes {
    std::span<const float> density;
    float mass = 0;
    bool given() const { return !density.empty(); }
};

struct ParticleSpans {
    std::span<float> x, y, z, vx, vy, vz;
    std::span<std::uint32_t> id;
    std::size_t size() const { return x.size(); }
    ConstPositions positions() const { return {x, y, z}; }
};

}  // namespace rivulet
