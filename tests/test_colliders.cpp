// Solid colliders for diffuse particles (Juckel & Beckhaus, "Rendering diffuse objects using particle systems
// inside voxelized surface geometry", §5.2), triangle meshes and the exact sphere and box: the
// segment-triangle test, inside/outside, the conservative box overlap that switches voxels off, and the
// collision response whose promise is that a particle starting outside never ends inside.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "jobs/segment_triangle.h"
#include "systems/diffuse/collider_mesh.h"
#include "systems/diffuse/solid_collider.h"

#include "support/counting_new.h"

using namespace rivulet;

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// ---------------------------------------------------------------------------------------------- meshes

void add_vertex(ColoredMesh& m, Vec3f p) {
    m.positions.insert(m.positions.end(), {p.x, p.y, p.z});
}

ColoredMesh octahedron(float r) {
    ColoredMesh m;
    for (const Vec3f p : {Vec3f{r, 0, 0}, Vec3f{-r, 0, 0}, Vec3f{0, r, 0}, Vec3f{0, -r, 0}, Vec3f{0, 0, r},
                          Vec3f{0, 0, -r}}) {
        add_vertex(m, p);
    }
    // Each face takes one of ±x, ±y, ±z; listed so that the winding is counter-clockwise from outside.
    m.indices = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    return m;
}

// An L-shaped prism: the polygon (0,0) (2,0) (2,1) (1,1) (1,2) (0,2), counter-clockwise, shifted by -1 so
// the reflex corner sits at the origin, extruded over |z| <= kLHalfDepth. Concave, so a reflected particle
// can hit the other arm.
constexpr float kLHalfDepth = 0.5f;
const float kLPolygon[6][2] = {{-1, -1}, {1, -1}, {1, 0}, {0, 0}, {0, 1}, {-1, 1}};

ColoredMesh l_prism() {
    ColoredMesh m;
    for (const float z : {-kLHalfDepth, kLHalfDepth}) {
        for (const auto& p : kLPolygon) add_vertex(m, {p[0], p[1], z});
    }
    // Caps: a fan from the reflex corner (index 3) sees every other vertex.
    for (std::uint32_t i : {4u, 5u, 0u, 1u}) {
        const std::uint32_t j = (i + 1) % 6;
        m.indices.insert(m.indices.end(), {6 + 3, 6 + i, 6 + j});  // top, +z
        m.indices.insert(m.indices.end(), {3, j, i});              // bottom, -z
    }
    for (std::uint32_t i = 0; i < 6; ++i) {
        const std::uint32_t j = (i + 1) % 6;
        m.indices.insert(m.indices.end(), {i, j, 6 + j, i, 6 + j, 6 + i});
    }
    return m;
}

bool inside_l(Vec3f p, float margin) {
    if (std::abs(p.z) >= kLHalfDepth - margin) return false;
    const bool lower = p.x > -1 + margin && p.x < 1 - margin && p.y > -1 + margin && p.y < -margin;
    const bool left = p.x > -1 + margin && p.x < -margin && p.y > -1 + margin && p.y < 1 - margin;
    return lower || left;
}

bool outside_l(Vec3f p, float margin) {
    return !inside_l(p, -margin);
}

// A torus around +z built here so these tests depend only on the collider: major radius 1, tube 0.35.
constexpr float kTorusMajor = 1.0f, kTorusMinor = 0.35f;

ColoredMesh torus(int nu, int nv) {
    ColoredMesh m;
    for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
            const float u = 2 * kPi * static_cast<float>(i) / static_cast<float>(nu);
            const float v = 2 * kPi * static_cast<float>(j) / static_cast<float>(nv);
            const float rho = kTorusMajor + kTorusMinor * std::cos(v);
            add_vertex(m, {rho * std::cos(u), rho * std::sin(u), kTorusMinor * std::sin(v)});
        }
    }
    auto id = [&](int i, int j) { return static_cast<std::uint32_t>((i % nu) * nv + (j % nv)); };
    for (int i = 0; i < nu; ++i) {
        for (int j = 0; j < nv; ++j) {
            // (u, v, outward) is right-handed, so u then v is counter-clockwise from outside.
            m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
            m.indices.insert(m.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
        }
    }
    return m;
}

float torus_distance(Vec3f p) {  // signed, to the true torus
    const float rho = std::sqrt(p.x * p.x + p.y * p.y) - kTorusMajor;
    return std::sqrt(rho * rho + p.z * p.z) - kTorusMinor;
}

// ---------------------------------------------------------------------------------------------- helpers

Vec3f corner_of(const ColliderMesh& c, std::size_t tri, int k) {
    const auto v = c.triangle_vertices();
    const std::size_t o = 9 * tri + 3 * static_cast<std::size_t>(k);
    return {v[o], v[o + 1], v[o + 2]};
}

// Brute force over every face plane: the truth for convex colliders, independent of the grid and the ray.
// +1 inside, -1 outside, 0 within `margin` of a plane that decides it.
int convex_side(const ColliderMesh& c, Vec3f p, float margin) {
    float worst = -1e30f;
    for (std::size_t t = 0; t < c.triangle_count(); ++t) {
        const Vec3f a = corner_of(c, t, 0), b = corner_of(c, t, 1), d = corner_of(c, t, 2);
        worst = std::max(worst, dot(p - a, normalize(cross(b - a, d - a))));
    }
    return worst < -margin ? 1 : worst > margin ? -1 : 0;
}

float inradius(const ColliderMesh& c) {
    float r = 1e30f;
    for (std::size_t t = 0; t < c.triangle_count(); ++t) {
        const Vec3f a = corner_of(c, t, 0), b = corner_of(c, t, 1), d = corner_of(c, t, 2);
        r = std::min(r, std::abs(dot(a, normalize(cross(b - a, d - a)))));
    }
    return r;
}

Vec3f random_in(std::mt19937& rng, Vec3f lo, Vec3f hi) {
    std::uniform_real_distribution<float> u(0, 1);
    return {lo.x + (hi.x - lo.x) * u(rng), lo.y + (hi.y - lo.y) * u(rng), lo.z + (hi.z - lo.z) * u(rng)};
}

Vec3f random_unit(std::mt19937& rng) {
    std::normal_distribution<float> n(0, 1);
    return normalize({n(rng), n(rng), n(rng)});
}

// -------------------------------------------------------------------------------------- segment_triangle

TEST(SegmentTriangle, HitsInTheMiddle) {
    const auto hit = segment_triangle({0.25f, 0.25f, 1}, {0.25f, 0.25f, -1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
    ASSERT_TRUE(hit);
    EXPECT_FLOAT_EQ(hit->t, 0.5f);
    EXPECT_EQ(hit->normal, (Vec3f{0, 0, 1}));
    EXPECT_TRUE(hit->front);
}

TEST(SegmentTriangle, BackFaceHitKeepsTheTrianglesNormal) {
    const auto hit = segment_triangle({0.25f, 0.25f, -1}, {0.25f, 0.25f, 3}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
    ASSERT_TRUE(hit);
    EXPECT_FLOAT_EQ(hit->t, 0.25f);
    EXPECT_EQ(hit->normal, (Vec3f{0, 0, 1}));
    EXPECT_FALSE(hit->front);
}

TEST(SegmentTriangle, Misses) {
    const Vec3f a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
    EXPECT_FALSE(segment_triangle({0.8f, 0.8f, 1}, {0.8f, 0.8f, -1}, a, b, c));      // beside the hypotenuse
    EXPECT_FALSE(segment_triangle({0.2f, 0.2f, 1}, {0.2f, 0.2f, 0.1f}, a, b, c));    // stops short
    EXPECT_FALSE(segment_triangle({0.2f, 0.2f, -0.1f}, {0.2f, 0.2f, -1}, a, b, c));  // starts past it
    EXPECT_FALSE(segment_triangle({-1, 0.2f, 0.5f}, {2, 0.2f, 0.5f}, a, b, c));      // parallel above
    EXPECT_FALSE(segment_triangle({-1, 0.2f, 0}, {2, 0.2f, 0}, a, b, c));            // parallel, in the plane
    EXPECT_FALSE(segment_triangle({0.2f, 0.2f, 1}, {0.2f, 0.2f, -1}, a, a, c));      // degenerate triangle
}

TEST(SegmentTriangle, EndpointOnThePlaneCounts) {
    const auto hit = segment_triangle({0.2f, 0.2f, 1}, {0.2f, 0.2f, 0}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0});
    ASSERT_TRUE(hit);
    EXPECT_FLOAT_EQ(hit->t, 1.0f);
}

// Two triangles sharing an edge, in general position, crossed by segments through points on that edge:
// whatever rounding does, the pair must not let the segment through.
TEST(SegmentTriangle, SharedEdgeIsWatertight) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0, 1);
    int both = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f p = random_in(rng, {-1, -1, -1}, {1, 1, 1}), q = random_in(rng, {-1, -1, -1}, {1, 1, 1});
        const Vec3f n = normalize(cross(q - p, random_unit(rng)));
        const Vec3f side = normalize(cross(n, q - p));
        // Wings on either side of the edge, slightly folded so the surface is not flat.
        const Vec3f r = p + (q - p) * u(rng) + side * (0.3f + u(rng)) + n * (0.2f * u(rng) - 0.1f);
        const Vec3f s = p + (q - p) * u(rng) - side * (0.3f + u(rng)) + n * (0.2f * u(rng) - 0.1f);
        const Vec3f on_edge = p + (q - p) * u(rng);
        const Vec3f dir = (random_unit(rng) * 0.5f + n) * (0.1f + 2 * u(rng));
        const Vec3f a = on_edge + dir, b = on_edge - dir * (0.1f + u(rng));
        const auto h1 = segment_triangle(a, b, p, q, r), h2 = segment_triangle(a, b, q, p, s);
        ASSERT_TRUE(h1 || h2) << "iteration " << i;
        both += h1 && h2;
    }
    EXPECT_GT(both, 0);  // the slack makes both report some of them; either is fine for collisions
}

// The same for an axis-aligned square split along its diagonal, hit exactly on the diagonal.
TEST(SegmentTriangle, DiagonalOfASquareIsWatertight) {
    const Vec3f a{0, 0, 0}, b{1, 0, 0}, c{1, 1, 0}, d{0, 1, 0};
    for (int i = 0; i <= 1000; ++i) {
        const float s = static_cast<float>(i) / 1000;
        for (const Vec3f dir : {Vec3f{0, 0, -1}, Vec3f{0.3f, -0.7f, -1}, Vec3f{-5, 5, -0.01f}}) {
            const Vec3f p0 = Vec3f{s, s, 0} - dir * 0.5f, p1 = Vec3f{s, s, 0} + dir * 0.5f;
            EXPECT_TRUE(segment_triangle(p0, p1, a, b, c) || segment_triangle(p0, p1, a, c, d)) << s;
        }
    }
}

// ------------------------------------------------------------------------------------------- contains

TEST(ColliderMesh, RejectsBadInput) {
    EXPECT_THROW(ColliderMesh::sphere(0), std::invalid_argument);
    EXPECT_THROW(ColliderMesh::sphere(std::nanf("")), std::invalid_argument);
    EXPECT_THROW(ColliderMesh::box({1, 0, 1}), std::invalid_argument);
    EXPECT_THROW(ColliderMesh::from_mesh(ColoredMesh{}), std::invalid_argument);
    ColoredMesh bad = octahedron(1);
    bad.positions[4] = std::nanf("");
    EXPECT_THROW(ColliderMesh::from_mesh(bad), std::invalid_argument);
    bad = octahedron(1);
    bad.indices[5] = 6;
    EXPECT_THROW(ColliderMesh::from_mesh(bad), std::invalid_argument);
}

TEST(ColliderMesh, ShapesAndBounds) {
    const ColliderMesh s = ColliderMesh::sphere(2);
    EXPECT_EQ(s.triangle_count(), 1280u);
    EXPECT_EQ(s.triangle_vertices().size(), 9 * 1280u);
    for (const float f : s.triangle_vertices()) EXPECT_LE(std::abs(f), 2.0f);
    for (std::size_t i = 0; i < s.triangle_vertices().size(); i += 3) {
        const auto v = s.triangle_vertices();
        EXPECT_NEAR(length({v[i], v[i + 1], v[i + 2]}), 2.0f, 1e-5f);  // vertices on the sphere
    }
    EXPECT_NEAR(s.bounds_min().x, -2, 1e-5f);
    EXPECT_NEAR(s.bounds_max().z, 2, 1e-5f);
    EXPECT_GT(inradius(s), 1.99f);

    const ColliderMesh b = ColliderMesh::box({1, 2, 3});
    EXPECT_EQ(b.triangle_count(), 12u);
    EXPECT_EQ(b.bounds_min(), (Vec3f{-1, -2, -3}));
    EXPECT_EQ(b.bounds_max(), (Vec3f{1, 2, 3}));
    // Outward winding: every face normal points away from the centre.
    for (std::size_t t = 0; t < b.triangle_count(); ++t) {
        const Vec3f p = corner_of(b, t, 0), q = corner_of(b, t, 1), r = corner_of(b, t, 2);
        EXPECT_GT(dot(cross(q - p, r - p), p + q + r), 0);
    }
}

TEST(ColliderMesh, ContainsMatchesABox) {
    const Vec3f h{1, 0.5f, 0.75f};
    const ColliderMesh b = ColliderMesh::box(h);
    std::mt19937 rng(1);
    for (int i = 0; i < 50000; ++i) {
        const Vec3f p = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        const float gap = std::max({std::abs(p.x) - h.x, std::abs(p.y) - h.y, std::abs(p.z) - h.z});
        if (std::abs(gap) < 1e-4f) continue;
        ASSERT_EQ(b.contains(p), gap < 0) << p.x << " " << p.y << " " << p.z;
    }
    // Rays along +x through the diagonals and edges of the triangulated faces.
    const ColliderMesh cube = ColliderMesh::box({1, 1, 1});
    for (int i = -9; i <= 9; ++i) {
        const float s = static_cast<float>(i) / 10;
        for (const float x : {-3.0f, -0.5f, 0.0f, 0.99f, 1.5f}) {
            EXPECT_EQ(cube.contains({x, s, s}), std::abs(x) < 1) << x << " " << s;
            EXPECT_EQ(cube.contains({x, s, -s}), std::abs(x) < 1) << x << " " << s;
        }
    }
    EXPECT_FALSE(cube.contains({std::nanf(""), 0, 0}));
}

TEST(ColliderMesh, ContainsMatchesTheSpherePolyhedron) {
    const ColliderMesh s = ColliderMesh::sphere(1.5f);
    std::mt19937 rng(2);
    for (int i = 0; i < 8000; ++i) {
        const Vec3f p = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        const int side = convex_side(s, p, 1e-5f);
        if (side == 0) continue;
        ASSERT_EQ(s.contains(p), side > 0) << p.x << " " << p.y << " " << p.z;
        if (length(p) < 1.45f) {  // well inside the true sphere
            ASSERT_TRUE(s.contains(p));
        }
        if (length(p) > 1.5f) {
            ASSERT_FALSE(s.contains(p));
        }
    }
    // Rays along +x exactly through vertices, and through edge midpoints: each crossing counts once.
    const auto v = s.triangle_vertices();
    for (std::size_t i = 0; i < v.size(); i += 27) {
        const Vec3f a{v[i], v[i + 1], v[i + 2]}, b{v[i + 3], v[i + 4], v[i + 5]};
        for (const Vec3f target : {a, (a + b) * 0.5f}) {
            for (const float back : {0.05f, 0.4f, 1.0f, 2.0f, 4.0f}) {
                const Vec3f p{target.x - back, target.y, target.z};
                const int side = convex_side(s, p, 1e-5f);
                if (side != 0) {
                    ASSERT_EQ(s.contains(p), side > 0) << i << " " << back;
                }
            }
        }
    }
}

TEST(ColliderMesh, ContainsMatchesATorus) {
    const ColliderMesh t = ColliderMesh::from_mesh(torus(48, 24));
    // The tessellation sits inside the true torus by at most the tube's sagitta plus the ring's.
    const float sag =
        kTorusMinor * (1 - std::cos(kPi / 24)) + (kTorusMajor + kTorusMinor) * (1 - std::cos(kPi / 48));
    std::mt19937 rng(3);
    int inside = 0;
    for (int i = 0; i < 50000; ++i) {
        const Vec3f p = random_in(rng, {-1.5f, -1.5f, -0.5f}, {1.5f, 1.5f, 0.5f});
        const float d = torus_distance(p);
        if (d < -2 * sag - 1e-3f) {
            ASSERT_TRUE(t.contains(p)) << p.x << " " << p.y << " " << p.z;
            ++inside;
        } else if (d > 1e-3f) {
            ASSERT_FALSE(t.contains(p)) << p.x << " " << p.y << " " << p.z;
        }
    }
    EXPECT_GT(inside, 1000);
    // Rays through vertices: points just behind each vertex along -x.
    const auto v = t.triangle_vertices();
    for (std::size_t i = 0; i < v.size(); i += 9) {
        for (const float back : {0.1f, 0.7f, 1.3f, 3.0f}) {
            const Vec3f p{v[i] - back, v[i + 1], v[i + 2]};
            const float d = torus_distance(p);
            if (d < -2 * sag - 1e-3f) {
                ASSERT_TRUE(t.contains(p));
            }
            if (d > 1e-3f) {
                ASSERT_FALSE(t.contains(p));
            }
        }
    }
}

TEST(ColliderMesh, ContainsMatchesAConcavePrism) {
    const ColliderMesh l = ColliderMesh::from_mesh(l_prism());
    std::mt19937 rng(4);
    for (int i = 0; i < 50000; ++i) {
        const Vec3f p = random_in(rng, {-1.5f, -1.5f, -1}, {1.5f, 1.5f, 1});
        if (inside_l(p, 1e-4f)) {
            ASSERT_TRUE(l.contains(p)) << p.x << " " << p.y << " " << p.z;
        }
        if (outside_l(p, 1e-4f)) {
            ASSERT_FALSE(l.contains(p)) << p.x << " " << p.y << " " << p.z;
        }
    }
    // Along y = 0.5 and y = -0.5 the +x ray runs level with the polygon's vertices and cap diagonals.
    for (const float y : {-0.5f, 0.5f, 0.0f + 1e-3f}) {
        for (const float z : {0.0f, 0.25f}) {
            for (const float x : {-2.0f, -0.5f, 0.5f}) {
                const Vec3f p{x, y, z};
                if (inside_l(p, 1e-4f) || outside_l(p, 1e-4f)) {
                    EXPECT_EQ(l.contains(p), inside_l(p, 0));
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------------------- overlaps_box

template <class Solid>
void expect_conservative_overlap(const Solid& c, std::uint32_t seed) {
    std::mt19937 rng(seed);
    const Vec3f lo = c.bounds_min() * 1.3f, hi = c.bounds_max() * 1.3f;
    std::uniform_real_distribution<float> size(0.002f, 0.4f);
    int touching = 0, clear = 0;
    for (int i = 0; i < 3000; ++i) {
        const Vec3f center = random_in(rng, lo, hi);
        const Vec3f half{size(rng), size(rng), size(rng)};
        const Vec3f blo = center - half, bhi = center + half;
        bool solid = false;
        for (int k = 0; k < 64 && !solid; ++k) {
            const Vec3f p =
                k < 8 ? Vec3f{(k & 1) ? bhi.x : blo.x, (k & 2) ? bhi.y : blo.y, (k & 4) ? bhi.z : blo.z}
                      : random_in(rng, blo, bhi);
            solid = c.contains(p);
        }
        const bool overlaps = c.overlaps_box(blo, bhi);
        if (solid) {
            ASSERT_TRUE(overlaps) << i;
        }
        touching += overlaps;
        clear += !overlaps;
    }
    EXPECT_GT(touching, 100);
    EXPECT_GT(clear, 100);
}

TEST(ColliderMesh, OverlapsBoxIsConservative) {
    expect_conservative_overlap(ColliderMesh::sphere(1), 11);
    expect_conservative_overlap(ColliderMesh::box({1, 0.3f, 0.6f}), 12);
    expect_conservative_overlap(ColliderMesh::from_mesh(l_prism()), 13);
    expect_conservative_overlap(ColliderMesh::from_mesh(torus(32, 16)), 14);
}

TEST(ColliderMesh, OverlapsBoxIsTightForABox) {
    const Vec3f h{1, 0.3f, 0.6f};
    const ColliderMesh b = ColliderMesh::box(h);
    std::mt19937 rng(15);
    for (int i = 0; i < 20000; ++i) {
        const Vec3f c = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        const Vec3f e = random_in(rng, {0.001f, 0.001f, 0.001f}, {0.5f, 0.5f, 0.5f});
        const float gap =
            std::max({std::abs(c.x) - h.x - e.x, std::abs(c.y) - h.y - e.y, std::abs(c.z) - h.z - e.z});
        if (std::abs(gap) < 1e-3f) continue;
        ASSERT_EQ(b.overlaps_box(c - e, c + e), gap < 0) << i;
    }
    EXPECT_TRUE(b.overlaps_box({-0.1f, -0.1f, -0.1f}, {0.1f, 0.1f, 0.1f}));  // wholly inside
    EXPECT_TRUE(b.overlaps_box({-5, -5, -5}, {5, 5, 5}));                    // wholly around
    EXPECT_FALSE(b.overlaps_box({1, 1, 1}, {-1, -1, -1}));                   // empty
}

// -------------------------------------------------------------------------------------------- collide

// Surface points that first steps aim at: the corners of a mesh's triangles and points on their edges.
std::vector<Vec3f> triangle_targets(const ColliderMesh& c, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0, 1);
    std::vector<Vec3f> targets;
    for (std::size_t k = 0; k < 400; ++k) {
        const std::size_t t = k % c.triangle_count();
        const Vec3f a = corner_of(c, t, 0), b = corner_of(c, t, 1);
        targets.push_back(k % 2 ? a : a + (b - a) * unit(rng));
    }
    return targets;
}

// Every step of every particle must end outside. Particles are pulled towards the origin by a spring so
// they keep coming back at all angles; restitution varies per particle (0 slides, 1 bounces fully). A
// tenth aim their first step straight at one of `targets` (corners, edges). `surely_inside` is
// independent of contains(), false when unsure.
template <class Solid>
void run_cloud(const char* name, const Solid& c, const std::function<bool(Vec3f)>& surely_inside,
               const std::vector<Vec3f>& targets, std::uint32_t seed) {
    constexpr int kParticles = 4000, kSteps = 150;
    constexpr float kDt = 0.08f, kSpring = 4.0f;
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(0, 1);
    const Vec3f lo = c.bounds_min() * 2.0f, hi = c.bounds_max() * 2.0f;
    std::vector<Vec3f> p(kParticles), v(kParticles);
    std::vector<float> e(kParticles);
    for (int i = 0; i < kParticles; ++i) {
        do p[i] = random_in(rng, lo, hi);
        while (c.contains(p[i]));
        v[i] = random_in(rng, {-3, -3, -3}, {3, 3, 3});
        e[i] = i % 10 == 0 ? 0.0f : i % 10 == 1 ? 1.0f : unit(rng);
    }
    for (int i = 0; i < kParticles; i += 10) {
        const Vec3f target = targets[static_cast<std::size_t>(i / 10) % targets.size()];
        const Vec3f from = target + random_unit(rng) * (0.2f + unit(rng));
        if (c.contains(from)) continue;
        p[i] = from;
        v[i] = (target - from) * ((1.0f + unit(rng)) / kDt);
    }
    long hits = 0;
    for (int step = 0; step < kSteps; ++step) {
        for (int i = 0; i < kParticles; ++i) {
            v[i] = v[i] - p[i] * (kSpring * kDt);
            Vec3f p1 = p[i] + v[i] * kDt;
            hits += c.collide(p[i], p1, v[i], e[i]);
            p[i] = p1;
        }
        for (int i = 0; i < kParticles; ++i) {
            ASSERT_FALSE(c.contains(p[i])) << name << " step " << step << " particle " << i;
            ASSERT_FALSE(surely_inside(p[i])) << name << " step " << step << " particle " << i;
            ASSERT_TRUE(finite(v[i]));
        }
    }
    EXPECT_GT(hits, kParticles) << name;  // the surface was crossed many times over
}

TEST(ColliderMesh, CollideNeverEndsInsideASphere) {
    const ColliderMesh s = ColliderMesh::sphere(1);
    const float r_in = inradius(s) - 1e-6f;
    run_cloud(
        "sphere", s, [&](Vec3f p) { return length(p) < r_in; }, triangle_targets(s, 21), 21);
}

TEST(ColliderMesh, CollideNeverEndsInsideABox) {
    const Vec3f h{1, 0.5f, 0.75f};
    const ColliderMesh b = ColliderMesh::box(h);
    run_cloud(
        "box", b, [&](Vec3f p) { return std::abs(p.x) < h.x && std::abs(p.y) < h.y && std::abs(p.z) < h.z; },
        triangle_targets(b, 22), 22);
}

TEST(ColliderMesh, CollideNeverEndsInsideAConcavePrism) {
    const ColliderMesh l = ColliderMesh::from_mesh(l_prism());
    run_cloud(
        "L prism", l, [](Vec3f p) { return inside_l(p, 0); }, triangle_targets(l, 23), 23);
}

TEST(ColliderMesh, CollideNeverEndsInsideAnOctahedron) {
    const ColliderMesh o = ColliderMesh::from_mesh(octahedron(1));
    run_cloud(
        "octahedron", o, [](Vec3f p) { return std::abs(p.x) + std::abs(p.y) + std::abs(p.z) < 1; },
        triangle_targets(o, 24), 24);
}

// Grazing steps: along a face, a hair above it, tilted slightly inwards, over edges and vertices.
TEST(ColliderMesh, CollideHandlesGrazingSteps) {
    const ColliderMesh s = ColliderMesh::sphere(1);
    std::mt19937 rng(25);
    std::uniform_real_distribution<float> unit(0, 1);
    for (std::size_t t = 0; t < s.triangle_count(); ++t) {
        const Vec3f a = corner_of(s, t, 0), b = corner_of(s, t, 1), c = corner_of(s, t, 2);
        const Vec3f n = normalize(cross(b - a, c - a));
        for (int k = 0; k < 8; ++k) {
            const Vec3f along = normalize(cross(n, random_unit(rng)));
            const Vec3f on = a + (b - a) * unit(rng) * 0.5f + (c - a) * unit(rng) * 0.5f;
            const Vec3f p0 = on + n * (1e-6f * static_cast<float>(k)) - along * 0.3f;
            if (s.contains(p0)) continue;
            Vec3f p1 = p0 + along * 0.6f - n * (1e-3f * unit(rng));
            Vec3f v = p1 - p0;
            s.collide(p0, p1, v, unit(rng));
            ASSERT_FALSE(s.contains(p1)) << t << " " << k;
        }
    }
}

TEST(ColliderMesh, HeadOnHitReversesTheNormalComponent) {
    const ColliderMesh b = ColliderMesh::box({1, 1, 1});
    for (const float e : {0.0f, 0.5f, 1.0f}) {
        Vec3f p1{0.2f, -0.3f, -1.0f};  // from z = 2, 3 units straight down: hits z = 1 after one unit
        Vec3f v{0, 0, -3};
        ASSERT_TRUE(b.collide({0.2f, -0.3f, 2}, p1, v, e));
        EXPECT_FLOAT_EQ(v.z, 3 * e);
        EXPECT_EQ(v.x, 0);
        EXPECT_NEAR(p1.z, 1 + 2 * e, 1e-3f);  // the remaining 2 units, mirrored and scaled
        EXPECT_GT(p1.z, 1);
        EXPECT_FLOAT_EQ(p1.x, 0.2f);
    }
    // Oblique: the tangential part is kept, the normal part reversed.
    Vec3f p1{1.2f, 0.4f, 0.0f}, v{1, 0, -2};
    ASSERT_TRUE(b.collide({0.2f, 0.4f, 2}, p1, v, 1));
    EXPECT_FLOAT_EQ(v.x, 1);
    EXPECT_FLOAT_EQ(v.z, 2);
    EXPECT_NEAR(p1.x, 1.2f, 1e-5f);
    EXPECT_NEAR(p1.z, 2.0f, 1e-3f);
    // A miss changes nothing.
    p1 = {3, 0, 2};
    v = {1, 0, 0};
    EXPECT_FALSE(b.collide({2, 0, 2}, p1, v, 1));
    EXPECT_EQ(p1, (Vec3f{3, 0, 2}));
    EXPECT_EQ(v, (Vec3f{1, 0, 0}));
}

TEST(ColliderMesh, StartingInsideIsLeftAlone) {
    const ColliderMesh b = ColliderMesh::box({1, 1, 1});
    Vec3f p1{3, 0, 0}, v{3, 0, 0};
    EXPECT_FALSE(b.collide({0, 0, 0}, p1, v, 1));
    EXPECT_EQ(p1, (Vec3f{3, 0, 0}));
}

// The scene moves the collider by an offset per frame; the caller maps both ends of the step into the
// collider's frame at their own times, and relative velocity is what reflects.
template <class Solid>
void expect_moving_solid_pushes_particles_out(const Solid& s) {
    auto offset = [](float t) { return Vec3f{1.5f * std::sin(2 * t), 0.6f * std::sin(3 * t), 4.0f}; };
    constexpr int kParticles = 4000, kSteps = 150;
    constexpr float kDt = 0.05f;
    std::mt19937 rng(31);
    std::vector<Vec3f> p(kParticles), v(kParticles);
    for (int i = 0; i < kParticles; ++i) {
        do p[i] = random_in(rng, {-2.5f, -1.5f, 3.0f}, {2.5f, 1.5f, 5.0f});
        while (s.contains(p[i] - offset(0)));
        v[i] = random_in(rng, {-0.2f, -0.2f, -0.2f}, {0.2f, 0.2f, 0.2f});
    }
    long hits = 0;
    for (int step = 0; step < kSteps; ++step) {
        const float t0 = static_cast<float>(step) * kDt, t1 = t0 + kDt;
        const Vec3f o0 = offset(t0), o1 = offset(t1), w = (o1 - o0) * (1 / kDt);
        for (int i = 0; i < kParticles; ++i) {
            Vec3f l1 = p[i] + v[i] * kDt - o1;
            Vec3f rel = v[i] - w;
            if (s.collide(p[i] - o0, l1, rel, 0.5f)) {
                ++hits;
                v[i] = rel + w;
            }
            p[i] = l1 + o1;
            ASSERT_FALSE(s.contains(p[i] - o1)) << "step " << step << " particle " << i;
        }
    }
    EXPECT_GT(hits, 1000);
}

TEST(ColliderMesh, MovingColliderPushesParticlesOut) {
    expect_moving_solid_pushes_particles_out(ColliderMesh::sphere(0.8f));
}

TEST(ColliderMesh, CollideIsThreadSafeAndAllocationFree) {
    const ColliderMesh s = ColliderMesh::sphere(1);
    constexpr int kParticles = 20000;
    std::mt19937 rng(41);
    std::vector<Vec3f> p0(kParticles), p1(kParticles), v(kParticles);
    for (int i = 0; i < kParticles; ++i) {
        do p0[i] = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        while (s.contains(p0[i]));
        v[i] = random_in(rng, {-10, -10, -10}, {10, 10, 10});
        p1[i] = p0[i] + v[i] * 0.1f;
    }
    std::vector<Vec3f> serial_p = p1, serial_v = v;
    const long before = test::allocation_count();
    for (int i = 0; i < kParticles; ++i) s.collide(p0[i], serial_p[i], serial_v[i], 0.7f);
    EXPECT_EQ(test::allocation_count(), before);

    std::vector<Vec3f> par_p = p1, par_v = v;
    std::vector<std::thread> threads;
    for (int k = 0; k < 4; ++k) {
        threads.emplace_back([&, k] {
            for (int i = k; i < kParticles; i += 4) s.collide(p0[i], par_p[i], par_v[i], 0.7f);
        });
    }
    for (auto& t : threads) t.join();
    for (int i = 0; i < kParticles; ++i) {
        ASSERT_EQ(par_p[i], serial_p[i]);
        ASSERT_EQ(par_v[i], serial_v[i]);
    }
}

// ------------------------------------------------------------------------------- analytic solids

TEST(SolidCollider, RejectsBadInput) {
    EXPECT_THROW(SolidCollider::sphere(0), std::invalid_argument);
    EXPECT_THROW(SolidCollider::sphere(std::nanf("")), std::invalid_argument);
    EXPECT_THROW(SolidCollider::sphere(std::numeric_limits<float>::infinity()), std::invalid_argument);
    EXPECT_THROW(SolidCollider::box({1, 0, 1}), std::invalid_argument);
    EXPECT_THROW(SolidCollider::box({1, std::nanf(""), 1}), std::invalid_argument);
    EXPECT_THROW(SolidCollider::mesh(ColoredMesh{}), std::invalid_argument);
}

TEST(SolidCollider, ContainsIsTheExactShape) {
    const SolidCollider s = SolidCollider::sphere(0.7f);
    const Vec3f h{1, 0.5f, 0.75f};
    const SolidCollider b = SolidCollider::box(h);
    EXPECT_EQ(s.bounds_max(), (Vec3f{0.7f, 0.7f, 0.7f}));
    EXPECT_EQ(b.bounds_min(), (Vec3f{-1, -0.5f, -0.75f}));
    std::mt19937 rng(51);
    for (int i = 0; i < 50000; ++i) {
        const Vec3f p = random_in(rng, {-1.5f, -1.5f, -1.5f}, {1.5f, 1.5f, 1.5f});
        if (std::abs(length(p) - 0.7f) > 1e-5f) {
            ASSERT_EQ(s.contains(p), length(p) < 0.7f) << i;
        }
        const float gap = std::max({std::abs(p.x) - h.x, std::abs(p.y) - h.y, std::abs(p.z) - h.z});
        if (std::abs(gap) > 1e-6f) {
            ASSERT_EQ(b.contains(p), gap < 0) << i;
        }
    }
    EXPECT_FALSE(b.contains(h));  // the surface is outside
    EXPECT_FALSE(s.contains({0, 0.7f, 0}));
    // A mesh solid is the mesh's own answer.
    const SolidCollider o = SolidCollider::mesh(octahedron(1));
    const ColliderMesh om = ColliderMesh::from_mesh(octahedron(1));
    for (int i = 0; i < 5000; ++i) {
        const Vec3f p = random_in(rng, {-1.2f, -1.2f, -1.2f}, {1.2f, 1.2f, 1.2f});
        ASSERT_EQ(o.contains(p), om.contains(p));
    }
    EXPECT_EQ(o.reach_radius(), om.reach_radius());
    int hits = 0;
    for (int i = 0; i < 5000; ++i) {
        const Vec3f p0 = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        const Vec3f p1 = p0 + random_unit(rng) * 2.0f;
        Vec3f pa = p1, pb = p1, va = p1 - p0, vb = p1 - p0;
        const bool ha = o.collide(p0, pa, va, 0.5f), hb = om.collide(p0, pb, vb, 0.5f);
        ASSERT_EQ(ha, hb);
        ASSERT_EQ(pa, pb);
        ASSERT_EQ(va, vb);
        hits += ha;
    }
    EXPECT_GT(hits, 100);
}

TEST(SolidCollider, OverlapsBoxIsConservativeAndTight) {
    const SolidCollider s = SolidCollider::sphere(1);
    const SolidCollider b = SolidCollider::box({1, 0.3f, 0.6f});
    expect_conservative_overlap(s, 52);
    expect_conservative_overlap(b, 53);
    std::mt19937 rng(54);
    for (int i = 0; i < 20000; ++i) {
        const Vec3f c = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        const Vec3f e = random_in(rng, {0.001f, 0.001f, 0.001f}, {0.5f, 0.5f, 0.5f});
        // Distance from the centre to the box, the truth for the sphere.
        const Vec3f q{std::max(std::abs(c.x) - e.x, 0.0f), std::max(std::abs(c.y) - e.y, 0.0f),
                      std::max(std::abs(c.z) - e.z, 0.0f)};
        if (std::abs(length(q) - 1) > 1e-3f) {
            ASSERT_EQ(s.overlaps_box(c - e, c + e), length(q) < 1) << i;
        }
    }
    EXPECT_TRUE(s.overlaps_box({-0.1f, -0.1f, -0.1f}, {0.1f, 0.1f, 0.1f}));  // wholly inside
    EXPECT_TRUE(s.overlaps_box({-5, -5, -5}, {5, 5, 5}));                    // wholly around
    EXPECT_FALSE(s.overlaps_box({0.8f, 0.8f, -0.1f}, {2, 2, 0.1f}));         // in the corner's gap
    EXPECT_FALSE(b.overlaps_box({1, 1, 1}, {-1, -1, -1}));                   // empty
}

// Surface points that first steps aim at: a sphere's anywhere; a box's corners and edges, the hard cases.
std::vector<Vec3f> sphere_targets(float r, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::vector<Vec3f> t(400);
    for (Vec3f& p : t) p = random_unit(rng) * r;
    return t;
}

std::vector<Vec3f> box_targets(Vec3f h, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Vec3f> t;
    for (int k = 0; k < 400; ++k) {
        const float sx = k & 1 ? 1.0f : -1.0f, sy = k & 2 ? 1.0f : -1.0f, sz = k & 4 ? 1.0f : -1.0f;
        Vec3f p{sx * h.x, sy * h.y, sz * h.z};  // a corner; from the eighth on, a point of an edge
        if (k >= 8) (k % 3 == 0 ? p.x : k % 3 == 1 ? p.y : p.z) *= u(rng);
        t.push_back(p);
    }
    return t;
}

TEST(SolidCollider, CollideNeverEndsInsideASphere) {
    run_cloud(
        "analytic sphere", SolidCollider::sphere(1), [](Vec3f p) { return length(p) < 1 - 1e-6f; },
        sphere_targets(1, 55), 55);
}

TEST(SolidCollider, CollideNeverEndsInsideABox) {
    const Vec3f h{1, 0.5f, 0.75f};
    run_cloud(
        "analytic box", SolidCollider::box(h),
        [&](Vec3f p) { return std::abs(p.x) < h.x && std::abs(p.y) < h.y && std::abs(p.z) < h.z; },
        box_targets(h, 56), 56);
}

TEST(SolidCollider, HeadOnHitReversesTheNormalComponent) {
    const SolidCollider s = SolidCollider::sphere(1);
    const SolidCollider b = SolidCollider::box({1, 1, 1});
    for (const float e : {0.0f, 0.5f, 1.0f}) {
        for (const SolidCollider* c : {&s, &b}) {
            Vec3f p1{0, 0, -1.0f};  // from z = 2, 3 units straight down: hits z = 1 after one unit
            Vec3f v{0, 0, -3};
            ASSERT_TRUE(c->collide({0, 0, 2}, p1, v, e));
            EXPECT_FLOAT_EQ(v.z, 3 * e);
            EXPECT_EQ(v.x, 0);
            EXPECT_NEAR(p1.z, 1 + c->skin() + 2 * e, 1e-5f);  // the remaining 2 units, mirrored and scaled
            EXPECT_GT(p1.z, 1);
        }
    }
    // Oblique on the sphere: at (0.6, 0, 0.8) the normal is the point itself; the step's rest reflects
    // about it and the tangential part of the velocity stays.
    Vec3f p1{0.6f, 0, 0.8f - 2}, v{0, 0, -2};
    ASSERT_TRUE(s.collide({0.6f, 0, 2}, p1, v, 1));
    const Vec3f n{0.6f, 0, 0.8f};
    EXPECT_NEAR(dot(v, n), 1.6f, 1e-5f);                        // -1.6 before
    EXPECT_NEAR(dot(v, Vec3f{0.8f, 0, -0.6f}), 1.2f, 1e-5f);    // tangential, unchanged
    EXPECT_NEAR(length(p1 - n * (1 + s.skin())), 2.0f, 1e-4f);  // 3.2 units, 1.2 to the hit
    // A miss changes nothing.
    p1 = {3, 0, 2};
    v = {1, 0, 0};
    EXPECT_FALSE(s.collide({2, 0, 2}, p1, v, 1));
    EXPECT_FALSE(b.collide({2, 0, 2}, p1, v, 1));
    EXPECT_EQ(p1, (Vec3f{3, 0, 2}));
    EXPECT_EQ(v, (Vec3f{1, 0, 0}));
}

// The box's triangles are the same planes, so away from its edges the two answers agree to rounding.
TEST(SolidCollider, BoxBouncesAsItsTriangles) {
    const Vec3f h{1, 0.5f, 0.75f};
    const SolidCollider b = SolidCollider::box(h);
    const ColliderMesh m = ColliderMesh::box(h);
    std::mt19937 rng(57);
    std::uniform_real_distribution<float> unit(0, 1);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3f p0 = random_in(rng, {-2, -2, -2}, {2, 2, 2});
        if (b.contains(p0)) continue;
        const Vec3f p1 = p0 + random_unit(rng) * (3 * unit(rng));
        const float e = unit(rng);
        Vec3f pb = p1, vb = p1 - p0, pm = p1, vm = p1 - p0;
        const bool hb = b.collide(p0, pb, vb, e), hm = m.collide(p0, pm, vm, e);
        // Within 1e-3 of an edge the two may pick different faces.
        bool edgy = false;
        for (float t = 0; t <= 1; t += 1.0f / 512) {
            const Vec3f q = p0 + (p1 - p0) * t;
            const int near = (std::abs(std::abs(q.x) - h.x) < 1e-3f) +
                             (std::abs(std::abs(q.y) - h.y) < 1e-3f) +
                             (std::abs(std::abs(q.z) - h.z) < 1e-3f);
            edgy |= near >= 2;
        }
        if (edgy) continue;
        ASSERT_EQ(hb, hm) << i;
        hits += hb;
        ASSERT_NEAR(length(pb - pm), 0, 1e-4f) << i;
        ASSERT_NEAR(length(vb - vm), 0, 1e-4f) << i;
    }
    EXPECT_GT(hits, 1000);
}

TEST(SolidCollider, GrazingAndInsideSteps) {
    const SolidCollider s = SolidCollider::sphere(1);
    const SolidCollider b = SolidCollider::box({1, 1, 1});
    std::mt19937 rng(58);
    std::uniform_real_distribution<float> unit(0, 1);
    for (int i = 0; i < 20000; ++i) {
        // Tangent to the sphere a hair above it, tilted slightly inwards.
        const Vec3f n = random_unit(rng);
        const Vec3f along = normalize(cross(n, random_unit(rng)));
        const Vec3f p0 = n * (1 + 1e-6f * float(i % 8)) - along * 0.3f;
        if (s.contains(p0)) continue;
        Vec3f p1 = p0 + along * 0.6f - n * (1e-3f * unit(rng)), v = p1 - p0;
        s.collide(p0, p1, v, unit(rng));
        ASSERT_FALSE(s.contains(p1)) << i;
        // Along a face of the box, on its plane or a hair inside it.
        const Vec3f q0{-1.5f, 2 * unit(rng) - 1, 1 - 1e-6f * float(i % 3)};
        Vec3f q1 = q0 + Vec3f{3, 0, -1e-3f * unit(rng)}, w = q1 - q0;
        if (b.contains(q0)) continue;
        b.collide(q0, q1, w, unit(rng));
        ASSERT_FALSE(b.contains(q1)) << i;
    }
    // Starting inside: left alone, so it can leave.
    for (const SolidCollider* c : {&s, &b}) {
        Vec3f p1{3, 0, 0}, v{3, 0, 0};
        EXPECT_FALSE(c->collide({0, 0, 0}, p1, v, 1));
        EXPECT_EQ(p1, (Vec3f{3, 0, 0}));
    }
}

TEST(SolidCollider, MovingSolidsPushParticlesOut) {
    expect_moving_solid_pushes_particles_out(SolidCollider::sphere(0.8f));
    expect_moving_solid_pushes_particles_out(SolidCollider::box({0.8f, 0.4f, 0.6f}));
}

}  // namespace
