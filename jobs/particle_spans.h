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

struct ParticleSpans {
    std::span<float> x, y, z, vx, vy, vz;
    std::span<std::uint32_t> id;
    std::size_t size() const { return x.size(); }
    ConstPositions positions() const { return {x, y, z}; }
};

}  // namespace rivulet
