#pragma once
// The back-to-front sort key of a point seen along a view direction (Juckel & Beckhaus, §4.4: transparent
// particles are drawn back to front): its depth quantized to 16 bits over a window and inverted, so
// ascending keys run from the farthest to the nearest.
#include <cstdint>

#include "jobs/vec3.h"

namespace rivulet {

inline constexpr std::uint32_t kDepthKeyBits = 16;
inline constexpr std::uint32_t kDepthKeyMax = (1u << kDepthKeyBits) - 1u;

// Depth along the view to key. Depths outside [min, max] clamp to its ends; NaN counts as depth_min
// (drawn last), so every input gives a defined key.
struct DepthKeyMap {
    Vec3f origin;
    Vec3f direction;  // need not be unit length: depths are measured in its units
    float depth_min = 0, depth_max = 1;

    float depth(float x, float y, float z) const {
        return (x - origin.x) * direction.x + (y - origin.y) * direction.y + (z - origin.z) * direction.z;
    }
    // Key steps per unit of depth; 0 when the range is empty (every key equal, order = index order).
    float scale() const {
        const float range = depth_max - depth_min;
        return range > 0 ? static_cast<float>(kDepthKeyMax + 1u) / range : 0.0f;
    }
    std::uint32_t key_of_depth(float d, float scale) const {
        const float s = (d - depth_min) * scale;
        const float q =
            s > 0.0f ? (s < static_cast<float>(kDepthKeyMax) ? s : static_cast<float>(kDepthKeyMax)) : 0.0f;
        return kDepthKeyMax - static_cast<std::uint32_t>(q);
    }
    std::uint32_t key(float x, float y, float z) const { return key_of_depth(depth(x, y, z), scale()); }
};

}  // namespace rivulet
