#pragma once
// Minimal value type for scene descriptions and small geometry; hot loops work on SoA spans instead.
#include <cmath>

namespace rivulet {

struct Vec3f {
    float x = 0, y = 0, z = 0;
    friend constexpr Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend constexpr Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend constexpr Vec3f operator*(Vec3f a, float s) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr bool operator==(Vec3f a, Vec3f b) = default;
};

constexpr float dot(Vec3f a, Vec3f b) {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
constexpr Vec3f cross(Vec3f a, Vec3f b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline bool finite(Vec3f a) {
    return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z);
}
inline float length(Vec3f a) {
    return std::sqrt(dot(a, a));
}
inline Vec3f normalize(Vec3f a) {
    const float l = length(a);
    return l > 0 ? a * (1.0f / l) : Vec3f{0, 1, 0};
}

}  // namespace rivulet
