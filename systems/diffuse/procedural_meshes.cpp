#include "systems/diffuse/procedural_meshes.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace rivulet {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

void require(bool ok, const char* what) {
    if (!ok) throw std::invalid_argument(what);
}

void push(std::vector<float>& to, Vec3f v) {
    to.insert(to.end(), {v.x, v.y, v.z});
}

// A closed surface around +y from a top pole to a bottom pole: rings 1 .. rings - 1 have `segments`
// vertices each at point(ring, phi) with phi from +x towards +z; point(0, .) and point(rings, .) are the
// poles (evaluated at phi = 0). Wound outward when the profile runs from top to bottom on the outside.
template <class Point>
ColoredMesh revolve(int rings, int segments, Point point) {
    ColoredMesh m;
    push(m.positions, point(0, 0.0f));
    for (int k = 1; k < rings; ++k)
        for (int j = 0; j < segments; ++j) push(m.positions, point(k, 2 * kPi * float(j) / float(segments)));
    push(m.positions, point(rings, 0.0f));
    const auto S = static_cast<std::uint32_t>(segments);
    const auto bottom = static_cast<std::uint32_t>(m.vertex_count() - 1);
    auto at = [&](int k, std::uint32_t j) { return 1 + std::uint32_t(k - 1) * S + j % S; };
    for (std::uint32_t j = 0; j < S; ++j) m.indices.insert(m.indices.end(), {0, at(1, j + 1), at(1, j)});
    for (int k = 1; k + 1 < rings; ++k)
        for (std::uint32_t j = 0; j < S; ++j)
            m.indices.insert(m.indices.end(), {at(k, j), at(k, j + 1), at(k + 1, j + 1), at(k, j),
                                               at(k + 1, j + 1), at(k + 1, j)});
    for (std::uint32_t j = 0; j < S; ++j)
        m.indices.insert(m.indices.end(), {bottom, at(rings - 1, j), at(rings - 1, j + 1)});
    return m;
}

float smoothstep(float e0, float e1, float x) {
    const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
    return t * t * (3 - 2 * t);
}

// The ghost's outline, radius against height from the neck down: a piecewise smooth blend through
// (height, radius) control points.
float body_radius(float y) {
    static constexpr float ys[] = {1.27f, 1.14f, 0.98f, 0.70f, 0.35f, 0.0f};
    static constexpr float rs[] = {0.232f, 0.205f, 0.28f, 0.33f, 0.37f, 0.41f};
    if (y >= ys[0]) return rs[0];
    for (int i = 0; i + 1 < 6; ++i)
        if (y >= ys[i + 1]) return rs[i] + (rs[i + 1] - rs[i]) * smoothstep(ys[i], ys[i + 1], y);
    return rs[5];
}

}  // namespace

ColoredMesh make_uv_sphere(Vec3f center, float radius, int slices, int stacks) {
    require(slices >= 3 && stacks >= 2, "make_uv_sphere: needs slices >= 3 and stacks >= 2");
    require(slices <= 1 << 14 && stacks <= 1 << 14, "make_uv_sphere: too many slices or stacks");
    require(radius > 0 && std::isfinite(radius) && finite(center), "make_uv_sphere: bad centre or radius");
    return revolve(stacks, slices, [&](int k, float phi) {
        const float theta = kPi * float(k) / float(stacks);
        const float r = radius * std::sin(theta);
        return center + Vec3f{r * std::cos(phi), radius * std::cos(theta), r * std::sin(phi)};
    });
}

ColoredMesh make_torus(Vec3f center, float major, float minor, int major_segments, int minor_segments) {
    require(major_segments >= 3 && minor_segments >= 3, "make_torus: needs at least 3 segments each way");
    require(major_segments <= 1 << 14 && minor_segments <= 1 << 14, "make_torus: too many segments");
    require(std::isfinite(major) && minor > 0 && minor < major && finite(center),
            "make_torus: needs 0 < minor < major");
    ColoredMesh m;
    const auto U = static_cast<std::uint32_t>(major_segments), V = static_cast<std::uint32_t>(minor_segments);
    for (std::uint32_t i = 0; i < U; ++i)
        for (std::uint32_t j = 0; j < V; ++j) {
            const float u = 2 * kPi * float(i) / float(U), v = 2 * kPi * float(j) / float(V);
            const float ring = major + minor * std::cos(v);
            push(m.positions, center + Vec3f{ring * std::cos(u), minor * std::sin(v), ring * std::sin(u)});
        }
    auto at = [&](std::uint32_t i, std::uint32_t j) { return (i % U) * V + j % V; };
    // d/dv x d/du points out of the tube.
    for (std::uint32_t i = 0; i < U; ++i)
        for (std::uint32_t j = 0; j < V; ++j)
            m.indices.insert(m.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j),
                                               at(i + 1, j + 1), at(i + 1, j)});
    return m;
}

ColoredMesh make_box_mesh(Vec3f min, Vec3f max) {
    require(finite(min) && finite(max) && min.x < max.x && min.y < max.y && min.z < max.z,
            "make_box_mesh: needs min < max on every axis");
    ColoredMesh m;
    for (int i = 0; i < 8; ++i)  // corner i: bit 0 x, bit 1 y, bit 2 z
        push(m.positions, {(i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z});
    // Each face's corners in counter-clockwise order seen from outside.
    static constexpr std::uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                                  {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& f : faces) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    return m;
}

ColoredMesh make_ghost_mesh() {
    constexpr int kSegments = 96;
    constexpr int kHeadRings = 26;   // top pole to the neck, over a 110 degree arc of the head
    constexpr int kBodyRings = 52;   // neck to hem
    constexpr int kUnderRings = 14;  // hem to the centre of the vaulted underside
    constexpr float kHeadY = 1.35f, kHeadR = 0.25f, kHeadArc = 110 * kPi / 180;
    constexpr float kVault = 0.32f;  // height of the underside's apex
    const float neck_y = kHeadY + kHeadR * std::cos(kHeadArc);
    auto hem_y = [](float phi) { return 0.04f * (1 + std::cos(7 * phi)); };  // lowest point at y = 0
    ColoredMesh m = revolve(kHeadRings + kBodyRings + kUnderRings, kSegments, [&](int k, float phi) {
        float r, y;
        if (k <= kHeadRings) {
            const float a = kHeadArc * float(k) / kHeadRings;
            r = kHeadR * std::sin(a), y = kHeadY + kHeadR * std::cos(a);
        } else if (k <= kHeadRings + kBodyRings) {
            const float t = float(k - kHeadRings) / kBodyRings;
            y = neck_y + (hem_y(phi) - neck_y) * t;
            r = kHeadR * std::sin(kHeadArc) + (body_radius(y) - body_radius(neck_y));
        } else {
            // Inward and up from the hem to the apex, staying well inside the flaring skirt.
            const float t = float(k - kHeadRings - kBodyRings) / kUnderRings;
            const float r_hem = kHeadR * std::sin(kHeadArc) + (body_radius(hem_y(phi)) - body_radius(neck_y));
            r = r_hem * (1 - t) * (1 - 0.15f * std::sin(kPi * t));
            y = hem_y(phi) + (kVault - hem_y(phi)) * std::sin(0.5f * kPi * t);
        }
        return Vec3f{r * std::cos(phi), y, r * std::sin(phi)};
    });

    const Vec3f body{0.86f, 0.93f, 1.0f}, glow{0.55f, 0.95f, 0.95f}, dark{0.02f, 0.03f, 0.12f};
    const Vec3f head{0, kHeadY, 0};
    auto on_head = [&](float x, float y) { return head + normalize(Vec3f{x, y, 1}) * kHeadR; };
    const Vec3f eyes[2] = {on_head(-0.36f, 0.2f), on_head(0.36f, 0.2f)};
    const Vec3f mouth = on_head(0, -0.42f);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const Vec3f p{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
        Vec3f c = body + (glow - body) * (1 - smoothstep(0.0f, 0.9f, p.y));
        if (length(p - eyes[0]) < 0.05f || length(p - eyes[1]) < 0.05f || length(p - mouth) < 0.035f)
            c = dark;
        push(m.colors, c);
    }
    return m;
}

}  // namespace rivulet
