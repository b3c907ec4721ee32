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
// camera target so it surrounds the view. A 3 x 3 grid of quads around the shadowed rectangle, which
// comes first: shared edges end at the same vertices, so no pixel falls between the pieces.
void add_ground(StaticGeometry& g, const SceneDesc& scene, GroundRect shadowed) {
    const float half = 60.0f, cx = scene.camera.target.x, cz = scene.camera.target.z, y = scene.ground_y;
    const float x0 = cx - half, x3 = cx + half, z0 = cz - half, z3 = cz + half;
    const float x1 = std::clamp(shadowed.x0, x0, x3), x2 = std::clamp(shadowed.x1, x1, x3);
    const float z1 = std::clamp(shadowed.z0, z0, z3), z2 = std::clamp(shadowed.z1, z1, z3);
    const float xs[4] = {x0, x1, x2, x3}, zs[4] = {z0, z1, z2, z3};
    const auto cell = [&](int i, int k) {
        if (xs[i] < xs[i + 1] && zs[k] < zs[k + 1])
            add_quad(g, {xs[i], y, zs[k]}, {xs[i], y, zs[k + 1]}, {xs[i + 1], y, zs[k + 1]},
                     {xs[i + 1], y, zs[k]}, {0, 1, 0});
    };
    g.ground.first = static_cast<std::uint32_t>(g.indices.size());
    cell(1, 1);
    g.ground.count = static_cast<std::uint32_t>(g.indices.size()) - g.ground.first;
    g.ground_far.first = static_cast<std::uint32_t>(g.indices.size());
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            if (i != 1 || k != 1) cell(i, k);
    g.ground_far.count = static_cast<std::uint32_t>(g.indices.size()) - g.ground_far.first;
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

// Beams along the box's twelve edges, outside the glass, so they frame the water without cutting into it.
// Those on the floor lie on it rather than under it when the tank stands on the ground.
void add_tank_frame(StaticGeometry& g, BoxCollider glass, float t, bool on_ground) {
    const float lo[3] = {glass.min.x, glass.min.y, glass.min.z},
                hi[3] = {glass.max.x, glass.max.y, glass.max.z};
    for (int axis = 0; axis < 3; ++axis) {
        const int b = (axis + 1) % 3, c = (axis + 2) % 3;
        for (int corner = 0; corner < 4; ++corner) {
            float beam_lo[3], beam_hi[3];
            beam_lo[axis] = lo[axis] - t, beam_hi[axis] = hi[axis] + t;
            if (axis == 1 && on_ground) beam_lo[axis] = lo[axis];
            for (int k : {b, c}) {
                const bool high = (k == b ? corner & 1 : corner & 2) != 0;
                if (high) {
                    beam_lo[k] = hi[k], beam_hi[k] = hi[k] + t;
                } else if (k == 1 && on_ground) {
                    beam_lo[k] = lo[k], beam_hi[k] = lo[k] + t;
                } else {
                    beam_lo[k] = lo[k] - t, beam_hi[k] = lo[k];
                }
            }
            add_box(g, {beam_lo[0], beam_lo[1], beam_lo[2]}, {beam_hi[0], beam_hi[1], beam_hi[2]});
        }
    }
}

// The walls (no lid; no floor on the ground), split by which side of them the camera is on.
void add_tank_glass(StaticGeometry& g, BoxCollider box, bool on_ground, Vec3f eye) {
    const Vec3f lo = box.min, hi = box.max;
    struct Wall {
        Vec3f a, b, c, d, n;
    };
    std::vector<Wall> walls = {
        {{lo.x, lo.y, lo.z}, {lo.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {lo.x, hi.y, lo.z}, {-1, 0, 0}},
        {{hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, {1, 0, 0}},
        {{lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, lo.y, lo.z}, {0, 0, -1}},
        {{lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, {0, 0, 1}},
    };
    if (!on_ground)
        walls.push_back(
            {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, {0, -1, 0}});
    const auto faces_camera = [&](const Wall& w) { return dot(w.n, eye - w.a) > 0; };
    for (bool front : {false, true}) {
        IndexRange& range = front ? g.glass_front : g.glass_back;
        range.first = static_cast<std::uint32_t>(g.indices.size());
        for (const Wall& w : walls)
            if (faces_camera(w) == front) add_quad(g, w.a, w.b, w.c, w.d, w.n);
        range.count = static_cast<std::uint32_t>(g.indices.size()) - range.first;
    }
}

bool tank_on_ground(const SceneDesc& scene) {
    return scene.sph.container.box.min.y <= scene.ground_y + 1e-4f;
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

BoxCollider tank_glass_box(const SceneDesc& scene) {
    const BoxCollider& c = scene.sph.container.box;
    const float gap = scene.particle_radius;
    BoxCollider box{c.min - Vec3f{gap, gap, gap}, c.max + Vec3f{gap, gap, gap}};
    if (tank_on_ground(scene)) box.min.y = scene.ground_y;
    return box;
}

float tank_frame_width(const SceneDesc& scene) {
    const Vec3f size = scene.sph.container.box.max - scene.sph.container.box.min;
    return std::clamp(0.015f * std::max({size.x, size.y, size.z}), 0.004f, 0.05f);
}

StaticGeometry build_static_geometry(const SceneDesc& scene, GroundRect shadowed) {
    StaticGeometry g;
    const auto range_since = [&](std::uint32_t first) {
        return IndexRange{first, static_cast<std::uint32_t>(g.indices.size()) - first};
    };
    add_ground(g, scene, shadowed);
    const auto solids = static_cast<std::uint32_t>(g.indices.size());
    for (const SphereCollider& s : scene.spheres) add_sphere(g, s);
    for (const BoxCollider& b : scene.boxes) add_box(g, b.min, b.max);
    if (scene.pool.enabled) add_pool_rim(g, scene);
    g.solids = range_since(solids);
    if (scene.simulation == SimulationKind::kDiffuse)
        for (const DiffuseCollider& c : scene.diffuse.colliders) {
            const auto first = static_cast<std::uint32_t>(g.indices.size());
            if (c.shape == "sphere") add_sphere(g, {{}, c.radius});
            if (c.shape == "box") add_box(g, Vec3f{} - c.half_extents, c.half_extents);
            g.movers.push_back(range_since(first));
        }
    if (scene.simulation == SimulationKind::kSph) {
        const auto frame = static_cast<std::uint32_t>(g.indices.size());
        add_tank_frame(g, tank_glass_box(scene), tank_frame_width(scene), tank_on_ground(scene));
        g.tank_frame = range_since(frame);
        add_tank_glass(g, tank_glass_box(scene), tank_on_ground(scene), scene.camera.eye);
    }
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
