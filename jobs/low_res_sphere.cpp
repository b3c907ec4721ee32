#include "jobs/low_res_sphere.h"

#include <algorithm>
#include <array>
#include <map>
#include <utility>

#include "jobs/vec3.h"

namespace rivulet {
namespace {

Vec3f vertex(const std::vector<float>& p, std::uint32_t i) {
    return {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
}

std::uint32_t push_unit(std::vector<float>& p, Vec3f v) {
    const Vec3f n = normalize(v);
    p.insert(p.end(), {n.x, n.y, n.z});
    return static_cast<std::uint32_t>(p.size() / 3 - 1);
}

// Winding is fixed up from geometry rather than trusted from a hand-typed table: a convex solid around
// the origin is outward-facing exactly when each face normal agrees with its centroid.
void orient_outward(const std::vector<float>& p, std::vector<std::uint32_t>& idx) {
    for (std::size_t t = 0; t < idx.size(); t += 3) {
        const Vec3f a = vertex(p, idx[t]), b = vertex(p, idx[t + 1]), c = vertex(p, idx[t + 2]);
        if (dot(cross(b - a, c - a), a + b + c) < 0) std::swap(idx[t + 1], idx[t + 2]);
    }
}

SphereTemplate build() {
    SphereTemplate s;
    const float g = 1.6180339887f;  // golden ratio: the icosahedron's vertices are (0, ±1, ±g) cycled
    const std::array<Vec3f, 12> ico = {{{-1, g, 0},
                                        {1, g, 0},
                                        {-1, -g, 0},
                                        {1, -g, 0},
                                        {0, -1, g},
                                        {0, 1, g},
                                        {0, -1, -g},
                                        {0, 1, -g},
                                        {g, 0, -1},
                                        {g, 0, 1},
                                        {-g, 0, -1},
                                        {-g, 0, 1}}};
    for (const Vec3f& v : ico) push_unit(s.positions, v);
    std::vector<std::uint32_t> faces = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                        4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                                        6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    orient_outward(s.positions, faces);

    // Midpoints are shared between the two faces of an edge so the result stays welded (closed).
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
        const std::pair<std::uint32_t, std::uint32_t> key{std::min(a, b), std::max(a, b)};
        const auto it = midpoint.find(key);
        if (it != midpoint.end()) return it->second;
        const std::uint32_t m = push_unit(s.positions, vertex(s.positions, a) + vertex(s.positions, b));
        midpoint.emplace(key, m);
        return m;
    };
    s.indices.reserve(faces.size() * 4);
    for (std::size_t t = 0; t < faces.size(); t += 3) {
        const std::uint32_t a = faces[t], b = faces[t + 1], c = faces[t + 2];
        const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
        s.indices.insert(s.indices.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    return s;
}

}  // namespace

const SphereTemplate& low_res_sphere() {
    static const SphereTemplate sphere = build();
    return sphere;
}

}  // namespace rivulet
