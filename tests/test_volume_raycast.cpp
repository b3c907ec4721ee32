// The density volume's raycast on real pixels. A volume is built here from one particle, F = V W_poly6(r)
// sampled at every lattice point of the bricks it reaches, so its iso-surface is the sphere of the radius
// where V W = iso; the depth the rays find is compared with that sphere's depth along each pixel's ray in
// double precision, across brick borders, atlas layers, solids in front and an eye inside the grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/png_writer.h"
#include "systems/render/renderer.h"
#include "systems/scenes/scene.h"

namespace rivulet {
namespace {

constexpr int kW = 160, kH = 120;

using test::facing_scene;

double poly6(double r2, double h) {
    if (r2 >= h * h) return 0;
    const double k = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9));
    const double d = h * h - r2;
    return k * d * d * d;
}

// A density volume owning its arrays, as the workers' slot would.
struct Volume {
    DensityGrid grid;
    float iso = 0;
    std::vector<std::int32_t> brick_slot;
    std::vector<std::uint32_t> slot_brick;
    std::vector<float> slot_min, slot_max, atlas;

    DensityVolumeView view() const { return {grid, iso, brick_slot, slot_brick, slot_min, slot_max, atlas}; }
    // Radius of the iso-surface around a lone particle: V W(r) = iso.
    double iso_radius() const {
        const double h = grid.h, k = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9));
        return std::sqrt(h * h - std::cbrt(double(iso) / (double(grid.volume) * k)));
    }
};

// One particle at `c`. Bricks whose samples are all zero are not stored, unless `store_empty`: then
// they are stored too, before the others, so the particle's bricks land in a later atlas layer.
Volume one_particle(const DensityGrid& g, Vec3f c, float iso, bool store_empty = false) {
    Volume v;
    v.grid = g;
    v.iso = iso;
    std::vector<std::vector<float>> samples(g.bricks());
    std::vector<bool> reached(g.bricks(), false);
    for (std::uint32_t bz = 0; bz < g.bz; ++bz)
        for (std::uint32_t by = 0; by < g.by; ++by)
            for (std::uint32_t bx = 0; bx < g.bx; ++bx) {
                const std::uint32_t b = g.brick_index(bx, by, bz);
                std::vector<float>& s = samples[b];
                s.resize(kBrickSamples);
                for (std::uint32_t k = 0; k < kBrickEdge; ++k)
                    for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                        for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                            const double dx = g.x(bx * kBrickCells + i) - double(c.x);
                            const double dy = g.y(by * kBrickCells + j) - double(c.y);
                            const double dz = g.z(bz * kBrickCells + k) - double(c.z);
                            const double f = g.volume * poly6(dx * dx + dy * dy + dz * dz, g.h);
                            s[(k * kBrickEdge + j) * kBrickEdge + i] = static_cast<float>(f);
                            reached[b] = reached[b] || f > 0;
                        }
            }
    v.brick_slot.assign(g.bricks(), -1);
    for (int pass = store_empty ? 0 : 1; pass < 2; ++pass)
        for (std::uint32_t b = 0; b < g.bricks(); ++b)
            if (reached[b] == (pass == 1)) {
                v.brick_slot[b] = static_cast<std::int32_t>(v.slot_brick.size());
                v.slot_brick.push_back(b);
            }
    const auto stored = static_cast<std::uint32_t>(v.slot_brick.size());
    v.atlas.assign(atlas_samples(atlas_layers(stored)), 0.0f);
    for (std::uint32_t slot = 0; slot < stored; ++slot) {
        const std::vector<float>& s = samples[v.slot_brick[slot]];
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                for (std::uint32_t i = 0; i < kBrickEdge; ++i)
                    v.atlas[atlas_offset(slot, i, j, k)] = s[(k * kBrickEdge + j) * kBrickEdge + i];
        v.slot_min.push_back(*std::min_element(s.begin(), s.end()));
        v.slot_max.push_back(*std::max_element(s.begin(), s.end()));
    }
    return v;
}

DensityGrid grid_at(Vec3f origin, float voxel, std::uint32_t bx, std::uint32_t by, std::uint32_t bz,
                    float h) {
    DensityGrid g;
    g.ox = origin.x, g.oy = origin.y, g.oz = origin.z;
    g.voxel = voxel;
    g.bx = bx, g.by = by, g.bz = bz;
    g.h = h;
    g.volume = 1;
    return g;
}

// The test's particle: h = 12 voxels of 0.05, the iso-surface about 0.4 from its centre.
constexpr float kVoxel = 0.05f, kH6 = 0.6f, kIso = 1.25f;
const Vec3f kCentre{0.1f, 0.55f, 0.2f};

Volume centre_volume() {
    // 5 x 4 x 5 bricks; the outer columns along x lie h or more from the particle and are not stored.
    return one_particle(grid_at({-0.9f, -0.3f, -0.8f}, kVoxel, 5, 4, 5, kH6), kCentre, kIso);
}

struct Hit {
    double depth = 0;  // along the view axis; 0 when the ray misses
    double chord = 0;  // length of the ray inside the sphere
};

// Where the ray through the centre of pixel (i, j) (row j from the bottom) meets the sphere.
Hit analytic_hit(const CameraDesc& cam, int i, int j, Vec3f c, double r) {
    const CameraBasis b = camera_basis(cam);
    const double hx = double(b.tan_half_fov_y) * kW / kH, hy = b.tan_half_fov_y;
    const double nx = (i + 0.5) / kW * 2 - 1, ny = (j + 0.5) / kH * 2 - 1;
    const double ray[3] = {b.forward.x + nx * hx * b.right.x + ny * hy * b.up.x,
                           b.forward.y + nx * hx * b.right.y + ny * hy * b.up.y,
                           b.forward.z + nx * hx * b.right.z + ny * hy * b.up.z};
    const double oc[3] = {double(b.eye.x) - c.x, double(b.eye.y) - c.y, double(b.eye.z) - c.z};
    const double A = ray[0] * ray[0] + ray[1] * ray[1] + ray[2] * ray[2];
    const double B = ray[0] * oc[0] + ray[1] * oc[1] + ray[2] * oc[2];
    const double C = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - r * r;
    const double disc = B * B - A * C;
    if (disc <= 0 || -B - std::sqrt(disc) <= 0) return {};
    return {(-B - std::sqrt(disc)) / A, 2 * std::sqrt(disc) / A * std::sqrt(A)};
}

std::unique_ptr<Renderer> make_renderer(const SceneDesc& scene = facing_scene(),
                                        VolumeRaycastSettings s = {}) {
    auto r = std::make_unique<Renderer>(RenderSettings{kW, kH});
    r->set_scene(scene);
    r->set_volume_raycast(s);
    return r;
}

void draw(Renderer& r, const Volume& v) {
    FrameView f;
    f.volume = v.view();
    r.render(f);
}

std::vector<float> read(const Renderer& r, VolumeBuffer which) {
    std::vector<float> out(std::size_t(kW) * kH);
    r.volume_pass().read(which, out);
    return out;
}

std::vector<std::uint8_t> picture(const Renderer& r) {
    std::vector<std::uint8_t> rgba(std::size_t(kW) * kH * 4);
    r.read_rgba(rgba);
    return rgba;
}

// With RIVULET_TEST_PICTURES=DIR set, the pictures the tests judge are written there to be looked at.
void keep_picture(const Renderer& r, const std::string& name) {
    const char* dir = std::getenv("RIVULET_TEST_PICTURES");
    if (!dir) return;
    write_png_rgba(std::string(dir) + "/" + name + ".png", kW, kH, picture(r));
}

struct Agreement {
    int hits = 0, misses = 0;
};

// Every pixel whose ray passes a voxel inside the iso sphere has its depth within half a voxel; every
// pixel whose ray passes more than a voxel outside it has no hit. `hidden(i, j)`: pixels to leave out.
template <typename Hidden>
Agreement expect_sphere(const std::vector<float>& depth, const CameraDesc& cam, Vec3f c, double r,
                        Hidden hidden) {
    Agreement a;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
            if (hidden(i, j)) continue;
            const float got = depth[std::size_t(j) * kW + i];
            if (analytic_hit(cam, i, j, c, r - kVoxel).depth > 0) {
                ++a.hits;
                EXPECT_NEAR(got, analytic_hit(cam, i, j, c, r).depth, 0.5 * kVoxel)
                    << "pixel " << i << ", " << j;
            } else if (analytic_hit(cam, i, j, c, r + kVoxel).depth == 0) {
                ++a.misses;
                EXPECT_EQ(got, 0.0f) << "pixel " << i << ", " << j;
            }
        }
    return a;
}

Agreement expect_sphere(const std::vector<float>& depth, const CameraDesc& cam, Vec3f c, double r) {
    return expect_sphere(depth, cam, c, r, [](int, int) { return false; });
}

}  // namespace

TEST(VolumeRaycast, DepthMatchesTheIsoSphereOfOneParticle) {
    const Volume v = centre_volume();
    ASSERT_LT(v.slot_brick.size(), std::size_t(v.grid.bricks()));  // some bricks are not stored
    const double r = v.iso_radius();
    ASSERT_GT(r, 6 * kVoxel);
    auto renderer = make_renderer();
    draw(*renderer, v);
    keep_picture(*renderer, "volume_sphere");
    const Agreement a =
        expect_sphere(read(*renderer, VolumeBuffer::kDepth), facing_scene().camera, kCentre, r);
    EXPECT_GT(a.hits, 1000);
    EXPECT_GT(a.misses, 10000);
}

TEST(VolumeRaycast, ThicknessIsTheChordThroughTheSphere) {
    const Volume v = centre_volume();
    const double r = v.iso_radius();
    auto renderer = make_renderer();
    draw(*renderer, v);
    const std::vector<float> t = read(*renderer, VolumeBuffer::kThickness);
    const std::vector<float> d = read(*renderer, VolumeBuffer::kDepth);
    int checked = 0;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
            const Hit inner = analytic_hit(facing_scene().camera, i, j, kCentre, r - kVoxel);
            const std::size_t k = std::size_t(j) * kW + i;
            if (inner.depth > 0) {
                // Away from the outline a ray crosses the sphere steeply: the two ends each err by
                // well under a voxel.
                if (inner.chord > 0.5 * r) {
                    EXPECT_NEAR(t[k], analytic_hit(facing_scene().camera, i, j, kCentre, r).chord, kVoxel)
                        << "pixel " << i << ", " << j;
                    ++checked;
                }
            } else if (d[k] == 0) {
                EXPECT_EQ(t[k], 0.0f) << "pixel " << i << ", " << j;
            }
        }
    EXPECT_GT(checked, 800);
}

TEST(VolumeRaycast, SurfaceAcrossABrickCornerHasNoGaps) {
    // The particle sits on the corner eight bricks share, seen along the two brick faces through it:
    // the rays near the picture's centre run inside those faces, where the walk changes brick.
    const DensityGrid g = grid_at({-0.8f, -0.3f, -0.8f}, kVoxel, 4, 4, 4, 0.35f);
    const Vec3f c{0.0f, 0.5f, 0.0f};
    float iso = 0;
    {
        const double k = 315.0 / (64.0 * std::numbers::pi * std::pow(0.35, 9));
        iso = static_cast<float>(k * std::pow(0.35 * 0.35 - 0.25 * 0.25, 3));  // r_iso = 0.25
    }
    const Volume v = one_particle(g, c, iso);
    ASSERT_EQ(v.slot_brick.size(), 8u);
    const double r = v.iso_radius();
    auto renderer = make_renderer();
    draw(*renderer, v);
    const std::vector<float> depth = read(*renderer, VolumeBuffer::kDepth);
    const Agreement a = expect_sphere(depth, facing_scene().camera, c, r);
    EXPECT_GT(a.hits, 300);
    // The picture's centre rows and columns (the brick faces' projections) are whole inside the sphere.
    const Hit centre = analytic_hit(facing_scene().camera, kW / 2, kH / 2, c, r);
    for (int o = -1; o <= 0; ++o) {
        for (int i = 0; i < kW; ++i) {
            if (analytic_hit(facing_scene().camera, i, kH / 2 + o, c, r - kVoxel).depth > 0) {
                EXPECT_GT(depth[std::size_t(kH / 2 + o) * kW + i], 0.0f) << "row " << kH / 2 + o << ", " << i;
            }
        }
        for (int j = 0; j < kH; ++j) {
            if (analytic_hit(facing_scene().camera, kW / 2 + o, j, c, r - kVoxel).depth > 0) {
                EXPECT_GT(depth[std::size_t(j) * kW + kW / 2 + o], 0.0f)
                    << "column " << kW / 2 + o << ", " << j;
            }
        }
    }
    EXPECT_NEAR(depth[std::size_t(kH / 2) * kW + kW / 2], centre.depth, 0.5 * kVoxel);
}

TEST(VolumeRaycast, ShadingHasNoSeamsAlongBrickFaces) {
    // The particle on an edge four bricks share, seen from close by along the vertical face x = 0.2
    // (between the ground's checker lines): the field's slope jumps across every lattice plane, and
    // normals taken inside one brick show those jumps as a line along the face. Across the face's
    // columns the picture must change no more than it does between the columns beside them. (The
    // horizontal face through the eye would lie along the horizon, which has an edge of its own.)
    SceneDesc scene = facing_scene();
    const Vec3f c{0.2f, 0.5f, 0.0f};
    scene.camera.eye = {c.x, c.y, 1.2f};
    scene.camera.target = c;
    const DensityGrid g = grid_at({-0.6f, -0.3f, -0.8f}, kVoxel, 4, 4, 4, 0.35f);
    const double k = 315.0 / (64.0 * std::numbers::pi * std::pow(0.35, 9));
    const Volume v = one_particle(g, c, static_cast<float>(k * std::pow(0.35 * 0.35 - 0.25 * 0.25, 3)));
    auto renderer = make_renderer(scene);
    draw(*renderer, v);
    keep_picture(*renderer, "volume_brick_faces");
    const std::vector<std::uint8_t> rgba = picture(*renderer);
    const auto step = [&](int x, int y) {  // between columns x - 1 and x
        int d = 0;
        for (int ch = 0; ch < 3; ++ch)
            d += std::abs(int(rgba[(std::size_t(y) * kW + x) * 4 + ch]) -
                          int(rgba[(std::size_t(y) * kW + x - 1) * 4 + ch]));
        return d;
    };
    // The face x = 0.2 lies between columns kW / 2 - 1 and kW / 2; the sphere covers about 40 rows
    // either side of the middle.
    int checked = 0;
    for (int y = kH / 2 - 30; y <= kH / 2 + 30; ++y) {
        if (std::abs(y - kH / 2) <= 2) continue;  // the horizon
        EXPECT_LE(step(kW / 2, y), 2 * std::max(step(kW / 2 - 2, y), step(kW / 2 + 2, y)) + 6) << "row " << y;
        ++checked;
    }
    EXPECT_GT(checked, 50);
}

TEST(VolumeRaycast, BricksInALaterAtlasLayerAndAGrowingAtlas) {
    // 12 x 12 x 8 bricks all stored, the empty ones first: the particle's bricks sit in the second
    // layer of the atlas. The same renderer draws one layer, then two (the atlas grows), then one.
    const Volume small = centre_volume();
    const Volume big = one_particle(grid_at({-2.3f, -1.8f, -1.4f}, kVoxel, 12, 12, 8, kH6), kCentre, kIso,
                                    /*store_empty=*/true);
    ASSERT_EQ(atlas_layers(static_cast<std::uint32_t>(big.slot_brick.size())), 2u);
    const auto brick_of = [](float x, float o) {
        return static_cast<std::uint32_t>((x - o) / (kVoxel * kBrickCells));
    };
    const std::uint32_t home = big.grid.brick_index(
        brick_of(kCentre.x, big.grid.ox), brick_of(kCentre.y, big.grid.oy), brick_of(kCentre.z, big.grid.oz));
    ASSERT_GE(big.brick_slot[home], std::int32_t(kAtlasLayerBricks));
    const double r = small.iso_radius();
    auto renderer = make_renderer();
    for (const Volume* v : {&small, &big, &small}) {
        draw(*renderer, *v);
        const Agreement a =
            expect_sphere(read(*renderer, VolumeBuffer::kDepth), facing_scene().camera, kCentre, r);
        EXPECT_GT(a.hits, 1000);
    }
}

TEST(VolumeRaycast, EyeInsideTheGridSeesTheSameSurface) {
    // The grid reaches past the camera (z = 3): no box face lies in front of the eye to draw.
    const Volume v = one_particle(grid_at({-1.0f, -0.3f, -1.0f}, kVoxel, 5, 4, 11, kH6), kCentre, kIso);
    auto renderer = make_renderer();
    draw(*renderer, v);
    const Agreement a =
        expect_sphere(read(*renderer, VolumeBuffer::kDepth), facing_scene().camera, kCentre, v.iso_radius());
    EXPECT_GT(a.hits, 1000);
    EXPECT_GT(a.misses, 10000);
}

TEST(VolumeRaycast, ClipBoxCutsTheWater) {
    // A pass of its own in the Renderer's context, over the picture the Renderer left: only x <= the
    // particle's x is water. Rays whose chord through the sphere lies wholly right of that plane find
    // none; rays entering the sphere left of it find the sphere as before.
    const Volume v = centre_volume();
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(facing_scene());
    r.render(FrameView{});
    VolumePass pass(kW, kH, {});
    const CameraDesc cam = facing_scene().camera;
    pass.set_camera(cam, {0, 1, 0});
    pass.set_clip({-10, -10, -10}, {kCentre.x, 10, 10});
    pass.render(v.view());
    std::vector<float> depth(std::size_t(kW) * kH);
    pass.read(VolumeBuffer::kDepth, depth);
    const double radius = v.iso_radius();
    const CameraBasis b = camera_basis(cam);
    int cut = 0, kept = 0;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i) {
            const Hit h = analytic_hit(cam, i, j, kCentre, radius);
            if (h.depth <= 0) continue;
            // x where the ray enters and leaves the sphere: x is linear in depth along the ray.
            const double rx = b.forward.x + ((i + 0.5) / kW * 2 - 1) * b.tan_half_fov_y * kW / kH * b.right.x;
            const double axial =
                h.chord /
                std::sqrt(1 + std::pow((i + 0.5) / kW * 2 - 1, 2) * std::pow(b.tan_half_fov_y * kW / kH, 2) +
                          std::pow((j + 0.5) / kH * 2 - 1, 2) * std::pow(b.tan_half_fov_y, 2));
            const double x_in = b.eye.x + h.depth * rx, x_out = b.eye.x + (h.depth + axial) * rx;
            const float got = depth[std::size_t(j) * kW + i];
            if (std::min(x_in, x_out) > kCentre.x + kVoxel) {
                EXPECT_EQ(got, 0.0f) << "pixel " << i << ", " << j;
                ++cut;
            } else if (x_in < kCentre.x - kVoxel &&
                       analytic_hit(cam, i, j, kCentre, radius - kVoxel).depth > 0) {
                EXPECT_NEAR(got, h.depth, 0.5 * kVoxel) << "pixel " << i << ", " << j;
                ++kept;
            }
        }
    EXPECT_GT(cut, 400);
    EXPECT_GT(kept, 400);
}

TEST(VolumeRaycast, SolidsInFrontHideTheWater) {
    // A slab between the camera and the left half of the sphere.
    SceneDesc scene = facing_scene();
    const BoxCollider slab{{-1.0f, 0.0f, 1.0f}, {0.1f, 1.2f, 1.1f}};
    scene.boxes.push_back(slab);
    const Volume v = centre_volume();
    auto renderer = make_renderer(scene);
    draw(*renderer, v);
    const std::vector<float> depth = read(*renderer, VolumeBuffer::kDepth);
    const CameraBasis b = camera_basis(scene.camera);
    // Whether the pixel's ray meets the slab grown by `margin`.
    const auto meets_slab = [&](int i, int j, double margin) {
        const double hx = double(b.tan_half_fov_y) * kW / kH, hy = b.tan_half_fov_y;
        const double nx = (i + 0.5) / kW * 2 - 1, ny = (j + 0.5) / kH * 2 - 1;
        const double o[3] = {b.eye.x, b.eye.y, b.eye.z};
        const double d[3] = {b.forward.x + nx * hx * b.right.x + ny * hy * b.up.x,
                             b.forward.y + nx * hx * b.right.y + ny * hy * b.up.y,
                             b.forward.z + nx * hx * b.right.z + ny * hy * b.up.z};
        const double lo[3] = {slab.min.x - margin, slab.min.y - margin, slab.min.z - margin};
        const double hi[3] = {slab.max.x + margin, slab.max.y + margin, slab.max.z + margin};
        double t0 = 0, t1 = 1e30;
        for (int a = 0; a < 3; ++a) {
            if (std::abs(d[a]) < 1e-12) {
                if (o[a] < lo[a] || o[a] > hi[a]) return false;
                continue;
            }
            double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
            if (ta > tb) std::swap(ta, tb);
            t0 = std::max(t0, ta), t1 = std::min(t1, tb);
        }
        return t0 < t1;
    };
    int hidden = 0;
    for (int j = 0; j < kH; ++j)
        for (int i = 0; i < kW; ++i)
            if (meets_slab(i, j, -0.01) &&
                analytic_hit(scene.camera, i, j, kCentre, v.iso_radius()).depth > 0) {
                EXPECT_EQ(depth[std::size_t(j) * kW + i], 0.0f) << "pixel " << i << ", " << j;
                ++hidden;
            }
    EXPECT_GT(hidden, 400);
    const Agreement a = expect_sphere(depth, scene.camera, kCentre, v.iso_radius(),
                                      [&](int i, int j) { return meets_slab(i, j, 0.01); });
    EXPECT_GT(a.hits, 400);
}

TEST(VolumeRaycast, WaterChangesOnlyThePixelsItCovers) {
    const Volume v = centre_volume();
    auto renderer = make_renderer();
    renderer->render(FrameView{});
    const std::vector<std::uint8_t> empty = picture(*renderer);
    draw(*renderer, v);
    keep_picture(*renderer, "volume_water");
    const std::vector<std::uint8_t> water = picture(*renderer);
    const std::vector<float> depth = read(*renderer, VolumeBuffer::kDepth);
    std::size_t hits = 0, changed_hits = 0, changed_elsewhere = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            // Pictures are read top row first, the targets bottom row first.
            const std::size_t p = (std::size_t(y) * kW + x) * 4;
            const bool hit = depth[std::size_t(kH - 1 - y) * kW + x] > 0;
            int diff = 0;
            for (int ch = 0; ch < 3; ++ch)
                diff = std::max(diff, std::abs(int(water[p + ch]) - int(empty[p + ch])));
            if (hit) {
                ++hits;
                changed_hits += diff > 8 ? 1 : 0;
            } else {
                changed_elsewhere += diff > 0 ? 1 : 0;
            }
        }
    EXPECT_GT(hits, 1000u);
    EXPECT_GT(changed_hits, hits * 95 / 100);
    EXPECT_EQ(changed_elsewhere, 0u);
    // The water's centre tends towards its colour: bluer than red, unlike the pale sky behind it.
    float px = 0, py = 0;
    ASSERT_TRUE(project_to_pixel(facing_scene().camera, kW, kH, kCentre, px, py));
    const std::size_t c = (std::size_t(py) * kW + std::size_t(px)) * 4;
    EXPECT_GT(int(water[c + 2]), int(water[c + 0]) + 20);

    // An empty volume afterwards draws nothing and leaves no hits behind.
    renderer->render(FrameView{});
    EXPECT_EQ(picture(*renderer), empty);
    const std::vector<float> after = read(*renderer, VolumeBuffer::kDepth);
    EXPECT_TRUE(std::all_of(after.begin(), after.end(), [](float d) { return d == 0.0f; }));
}

TEST(VolumeRaycast, TimesItsPartsWhenAsked) {
    VolumeRaycastSettings s;
    s.time_passes = true;
    auto renderer = make_renderer(facing_scene(), s);
    renderer->set_time_passes(true);
    draw(*renderer, centre_volume());
    EXPECT_GT(renderer->timings().volume_upload, 0.0);
    EXPECT_GT(renderer->timings().volume, 0.0);
    EXPECT_GT(renderer->volume_pass().timings().upload, 0.0);
    EXPECT_GT(renderer->volume_pass().timings().raycast, 0.0);
}

TEST(VolumeRaycast, BadSettingsAndBadVolumesAreClearErrors) {
    VolumeRaycastSettings s;
    EXPECT_EQ(s.validate(), "");
    s.step = 0;
    EXPECT_NE(s.validate().find("step"), std::string::npos);
    s.step = 0.75f;
    EXPECT_NE(s.validate().find("(0, 0.5]"), std::string::npos);
    s = {};
    s.refine = -1;
    EXPECT_NE(s.validate().find("refinement"), std::string::npos);
    Renderer r(RenderSettings{kW, kH});
    EXPECT_THROW(r.set_volume_raycast(s), std::invalid_argument);

    // A volume before the pass exists, and a brick naming a slot that is not stored.
    const Volume good = centre_volume();
    FrameView f;
    f.volume = good.view();
    EXPECT_THROW(r.render(f), std::out_of_range);
    r.set_volume_raycast({});
    Volume bad = good;
    bad.brick_slot[bad.slot_brick[0]] = static_cast<std::int32_t>(bad.slot_min.size());
    f.volume = bad.view();
    EXPECT_THROW(r.render(f), std::out_of_range);
    Volume short_atlas = good;
    short_atlas.atlas.resize(100);
    f.volume = short_atlas.view();
    EXPECT_THROW(r.render(f), std::out_of_range);
}

}  // namespace rivulet
