#include "systems/render/scene_geometry.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

namespace rivulet {
namespace {

void push_vertex(StaticGeometry& g, Vec3f p, Vec3f n) {
    g.vertices.insert(g.vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
}

std::uint32_t vertex_count(const StaticGeometry& g) {
    return static_cast<std::uint32_t>(g.vertices.size() / 6);
}

void add_quad(StaticGeometry& g, Vec3f a, Vec3f b, Vec3f c, Vec3f d, Vec3f n) {
    const std::uint32_t first = vertex_count(g);
    for (Vec3f p : {a, b, c, d}) push_vertex(g, p, n);
    g.indices.insert(g.indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
}

// The ground is large but finite: it reaches past the fog distance of the shader, centred under the
// camera target so it surrounds the view.
void add_ground(StaticGeometry& g, const SceneDesc& scene) {
    const float half = 60.0f, cx = scene.camera.target.x, cz = scene.camera.target.z, y = scene.ground_y;
    add_quad(g, {cx - half, y, cz - half}, {cx - half, y, cz + half}, {cx + half, y, cz + half},
             {cx + half, y, cz - half}, {0, 1, 0});
}

void add_box(StaticGeometry& g, Vec3f lo, Vec3f hi) {
    add_quad(g, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, {1, 0, 0});
    add_quad(g, {lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, {-1, 0, 0});
    add_quad(g, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}, {hi.x, hi.y, lo.z}, {0, 1, 0});
    add_quad(g, {lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, {0, -1, 0});
    add_quad(g, {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, {0, 0, 1});
    add_quad(g, {lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z}, {0, 0, -1});
}

// Colliders are big and in plain view, so they get a smoother sphere than the particles' icosphere.
void add_sphere(StaticGeometry& g, const SphereCollider& s) {
    constexpr std::uint32_t kSlices = 32, kStacks = 20;
    const float pi = std::numbers::pi_v<float>;
    const std::uint32_t first = vertex_count(g);
    for (std::uint32_t i = 0; i <= kStacks; ++i) {
        const float theta = pi * static_cast<float>(i) / kStacks;
        for (std::uint32_t j = 0; j <= kSlices; ++j) {
            const float phi = 2 * pi * static_cast<float>(j) / kSlices;
            const Vec3f n{std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
            push_vertex(g, s.center + n * s.radius, n);
        }
    }
    for (std::uint32_t i = 0; i < kStacks; ++i) {
        for (std::uint32_t j = 0; j < kSlices; ++j) {
            const std::uint32_t a = first + i * (kSlices + 1) + j, b = a + kSlices + 1;
            g.indices.insert(g.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
    }
}

// A low wall around the pool so its water edge does not float in the air when level > ground.
void add_pool_rim(StaticGeometry& g, const SceneDesc& scene) {
    const PoolDesc& p = scene.pool;
    const float t = 0.02f * std::max(p.size_x, p.size_z);
    const float y0 = std::min(scene.ground_y, p.level), y1 = std::max(scene.ground_y, p.level) + t * 0.5f;
    const float x0 = p.x0, x1 = p.x0 + p.size_x, z0 = p.z0, z1 = p.z0 + p.size_z;
    add_box(g, {x0 - t, y0, z0 - t}, {x1 + t, y1, z0});
    add_box(g, {x0 - t, y0, z1}, {x1 + t, y1, z1 + t});
    add_box(g, {x0 - t, y0, z0}, {x0, y1, z1});
    add_box(g, {x1, y0, z0}, {x1 + t, y1, z1});
}

}  // namespace

StaticGeometry build_static_geometry(const SceneDesc& scene) {
    StaticGeometry g;
    add_ground(g, scene);
    g.ground_index_count = static_cast<std::uint32_t>(g.indices.size());
    for (const SphereCollider& s : scene.spheres) add_sphere(g, s);
    for (const BoxCollider& b : scene.boxes) add_box(g, b.min, b.max);
    if (scene.pool.enabled) add_pool_rim(g, scene);
    return g;
}

void write_grid_indices(int nx, int nz, std::span<std::uint32_t> out) {
    assert(out.size() == std::size_t(nx - 1) * std::size_t(nz - 1) * 6u);
    std::size_t n = 0;
    const auto w = static_cast<std::uint32_t>(nx);
    for (std::uint32_t iz = 0; iz + 1 < static_cast<std::uint32_t>(nz); ++iz) {
        for (std::uint32_t ix = 0; ix + 1 < w; ++ix) {
            const std::uint32_t a = iz * w + ix, b = a + 1, c = a + w, d = c + 1;
            // +z runs down the rows; this order is counter-clockwise seen from above (+y).
            out[n++] = a, out[n++] = c, out[n++] = b;
            out[n++] = b, out[n++] = c, out[n++] = d;
        }
    }
}

void write_height_field_vertices(const HeightFieldView& f, std::span<float> out) {
    assert(out.size() == std::size_t(f.nx) * std::size_t(f.nz) * 6u);
    const std::size_t nx = static_cast<std::size_t>(f.nx), nz = static_cast<std::size_t>(f.nz);
    for (std::size_t iz = 0; iz < nz; ++iz) {
        const std::size_t zm = iz > 0 ? iz - 1 : iz, zp = iz + 1 < nz ? iz + 1 : iz;
        for (std::size_t ix = 0; ix < nx; ++ix) {
            const std::size_t xm = ix > 0 ? ix - 1 : ix, xp = ix + 1 < nx ? ix + 1 : ix;
            const float* h = f.heights.data();
            const float dhdx = (h[iz * nx + xp] - h[iz * nx + xm]) / (static_cast<float>(xp - xm) * f.dx);
            const float dhdz = (h[zp * nx + ix] - h[zm * nx + ix]) / (static_cast<float>(zp - zm) * f.dz);
            const Vec3f n = normalize(Vec3f{-dhdx, 1, -dhdz});
            float* o = out.data() + (iz * nx + ix) * 6u;
            o[0] = f.x0 + static_cast<float>(ix) * f.dx;
            o[1] = h[iz * nx + ix];
            o[2] = f.z0 + static_cast<float>(iz) * f.dz;
            o[3] = n.x, o[4] = n.y, o[5] = n.z;
        }
    }
}

}  // namespace rivulet
