// Marching cubes over a sparse density volume (jobs/volume_marching_cubes.h, systems/volume/volume_mesh.h)
// on volumes built here from analytic fields, with the bricks no field value reaches left unstored: the
// same triangles as plain marching cubes over the whole lattice, one vertex per crossed lattice edge,
// vertices on the analytic surface, normals out of the fluid, watertight and consistently oriented
// across brick borders, the enclosed volume of a ball, the same bytes at any thread count.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <numbers>
#include <stdexcept>
#include <utility>
#include <vector>

#include "jobs/density_volume.h"
#include "jobs/marching_tables.h"
#include "jobs/volume_marching_cubes.h"
#include "support/reference_marching_cubes.h"
#include "systems/volume/volume_mesh.h"

using namespace rivulet;

namespace {

using Field = std::function<double(double, double, double)>;

// A density volume owning its memory, filled brick by brick from a field of world position; every brick
// with a non-zero sample is stored (so an unstored brick is F = 0 on all its samples, faces included, as
// the builder guarantees), in brick order or the reverse.
struct Volume {
    DensityGrid grid;
    float iso = 0.5f;
    std::vector<std::int32_t> brick_slot;
    std::vector<std::uint32_t> slot_brick;
    std::vector<float> slot_min, slot_max, atlas;
    DensityVolumeView view() const { return {grid, iso, brick_slot, slot_brick, slot_min, slot_max, atlas}; }
};

Volume make_volume(const DensityGrid& grid, float iso, const Field& f, bool reverse_slots = false) {
    Volume v;
    v.grid = grid;
    v.iso = iso;
    v.brick_slot.assign(grid.bricks(), -1);
    std::vector<std::vector<float>> bricks;
    for (std::uint32_t n = 0; n < grid.bricks(); ++n) {
        const std::uint32_t id = reverse_slots ? grid.bricks() - 1 - n : n;
        const std::uint32_t a = id % grid.bx, b = (id / grid.bx) % grid.by, c = id / (grid.bx * grid.by);
        std::vector<float> s(kBrickSamples);
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                for (std::uint32_t i = 0; i < kBrickEdge; ++i)
                    s[(k * kBrickEdge + j) * kBrickEdge + i] =
                        static_cast<float>(f(grid.x(a * kBrickCells + i), grid.y(b * kBrickCells + j),
                                             grid.z(c * kBrickCells + k)));
        if (std::all_of(s.begin(), s.end(), [](float x) { return x == 0.0f; })) continue;
        v.brick_slot[id] = static_cast<std::int32_t>(v.slot_brick.size());
        v.slot_brick.push_back(id);
        v.slot_min.push_back(*std::min_element(s.begin(), s.end()));
        v.slot_max.push_back(*std::max_element(s.begin(), s.end()));
        bricks.push_back(std::move(s));
    }
    v.atlas.assign(atlas_samples(atlas_layers(static_cast<std::uint32_t>(bricks.size()))), 0.0f);
    for (std::uint32_t slot = 0; slot < bricks.size(); ++slot)
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                for (std::uint32_t i = 0; i < kBrickEdge; ++i)
                    v.atlas[atlas_offset(slot, i, j, k)] =
                        bricks[slot][(k * kBrickEdge + j) * kBrickEdge + i];
    return v;
}

DensityGrid grid_of(std::uint32_t bricks, float voxel, float ox = -1.0f, float oy = 0.5f, float oz = -2.0f) {
    DensityGrid g;
    g.ox = ox, g.oy = oy, g.oz = oz;
    g.voxel = voxel;
    g.bx = g.by = g.bz = bricks;
    return g;
}

struct Ball {
    double c[3];
    double support;  // F = max(0, 1 - |p - c|^2 / support^2); F = 0.5 at support / sqrt(2)
    double operator()(double x, double y, double z) const {
        const double d2 = (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2]);
        return std::max(0.0, 1.0 - d2 / (support * support));
    }
    double iso_radius() const { return support / std::sqrt(2.0); }
};

// A ball of 16 voxels' support (11.3 voxels to F = 0.5) off the lattice points, over 5^3 bricks: it crosses
// brick borders along every axis and leaves the corner bricks unstored.
constexpr float kVoxel = 0.25f;
Ball ball_in(const DensityGrid& g) {
    return {{g.ox + 20.3 * g.voxel, g.oy + 19.6 * g.voxel, g.oz + 20.7 * g.voxel}, 16.0 * g.voxel};
}

// A torus of major radius 10 voxels round an oblique axis, its tube F = 0.5 at 2.8 voxels: genus one,
// crossing brick borders along every axis at all sorts of angles.
struct Torus {
    double c[3], n[3];
    double major, support;
    double operator()(double x, double y, double z) const {
        const double p[3] = {x - c[0], y - c[1], z - c[2]};
        const double h = p[0] * n[0] + p[1] * n[1] + p[2] * n[2];
        const double rho = std::sqrt(std::max(0.0, p[0] * p[0] + p[1] * p[1] + p[2] * p[2] - h * h));
        const double d2 = (rho - major) * (rho - major) + h * h;
        return std::max(0.0, 1.0 - d2 / (support * support));
    }
};
Torus torus_in(const DensityGrid& g) {
    const double len = std::sqrt(1.0 + 0.49 + 0.16);
    return {{g.ox + 16.4 * g.voxel, g.oy + 15.7 * g.voxel, g.oz + 16.2 * g.voxel},
            {1.0 / len, 0.7 / len, 0.4 / len},
            10.0 * g.voxel,
            4.0 * g.voxel};
}

// Plain marching cubes over every cell of the lattice through DensityVolumeView::sample, one vertex per
// crossed edge found in a map: slow and simple on purpose.
test::ReferenceMesh plain_marching_cubes(const DensityVolumeView& v) {
    const MarchingTables& mt = marching_tables();
    const DensityGrid& g = v.grid;
    test::ReferenceMesh out;
    std::map<std::array<std::uint32_t, 4>, std::uint32_t> vertex_of;
    for (std::uint32_t k = 0; k + 1 < g.samples_z(); ++k)
        for (std::uint32_t j = 0; j + 1 < g.samples_y(); ++j)
            for (std::uint32_t i = 0; i + 1 < g.samples_x(); ++i) {
                float f[8];
                unsigned mask = 0;
                for (unsigned c = 0; c < 8; ++c) {
                    f[c] = v.sample(i + (c & 1u), j + ((c >> 1) & 1u), k + ((c >> 2) & 1u));
                    if (f[c] >= v.iso) mask |= 1u << c;
                }
                for (std::uint32_t q = 0; q < mt.triangle_count[mask] * 3u; ++q) {
                    const auto e = static_cast<std::uint32_t>(mt.triangles[mask][q]);
                    const std::uint32_t axis = mt.edge_axis[e], lc = mt.edge_corner[e][0],
                                        hc = mt.edge_corner[e][1];
                    const std::array<std::uint32_t, 4> key = {i + (lc & 1u), j + ((lc >> 1) & 1u),
                                                              k + ((lc >> 2) & 1u), axis};
                    auto [it, fresh] = vertex_of.emplace(key, std::uint32_t(out.positions.size() / 3));
                    if (fresh) {
                        float p[3] = {g.x(key[0]), g.y(key[1]), g.z(key[2])};
                        p[axis] += (v.iso - f[lc]) / (f[hc] - f[lc]) * g.voxel;
                        out.positions.insert(out.positions.end(), p, p + 3);
                    }
                    out.indices.push_back(it->second);
                }
            }
    return out;
}

void expect_same_triangles_as_plain_marching_cubes(const Volume& vol, const TriangleMesh& m) {
    const test::ReferenceMesh ref = plain_marching_cubes(vol.view());
    ASSERT_GT(ref.indices.size(), 0u);
    EXPECT_EQ(m.vertex_count(), ref.positions.size() / 3) << "one vertex per crossed lattice edge";
    ASSERT_EQ(m.indices.size(), ref.indices.size());
    // Same interpolation from the same sample values: the positions agree exactly.
    EXPECT_EQ(test::canonical_triangles(m.vertices, 6, m.indices),
              test::canonical_triangles(ref.positions, 3, ref.indices));
}

// Closed and consistently oriented: every directed edge once, its reverse once, and no two vertices at
// one position (welding by index is welding by position). Returns V - E + F.
long expect_watertight(const TriangleMesh& m) {
    std::vector<std::array<float, 3>> pos;
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        pos.push_back({m.vertices[6 * v], m.vertices[6 * v + 1], m.vertices[6 * v + 2]});
    std::sort(pos.begin(), pos.end());
    EXPECT_EQ(std::adjacent_find(pos.begin(), pos.end()), pos.end()) << "two vertices at one position";
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (std::size_t t = 0; t < m.indices.size(); t += 3)
        for (int e = 0; e < 3; ++e) ++directed[{m.indices[t + e], m.indices[t + (e + 1) % 3]}];
    std::size_t bad = 0;
    for (const auto& [edge, n] : directed) {
        const auto back = directed.find({edge.second, edge.first});
        if (n != 1 || back == directed.end() || back->second != 1) ++bad;
    }
    EXPECT_EQ(bad, 0u) << "directed edges not matched by exactly one opposite edge";
    return long(m.vertex_count()) - long(directed.size() / 2) + long(m.triangle_count());
}

// Geometric normals (counter-clockwise) against the vertex normals and the field's outward direction
// `out(centroid)`; counts the triangles that disagree.
template <class Out>
std::size_t count_misoriented(const TriangleMesh& m, const Out& out) {
    std::size_t bad = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const float* a = m.vertices.data() + 6 * m.indices[t];
        const float* b = m.vertices.data() + 6 * m.indices[t + 1];
        const float* c = m.vertices.data() + 6 * m.indices[t + 2];
        const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double w[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        const double n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        double vn = 0, radial = 0;
        const double centroid[3] = {(double(a[0]) + b[0] + c[0]) / 3, (double(a[1]) + b[1] + c[1]) / 3,
                                    (double(a[2]) + b[2] + c[2]) / 3};
        const std::array<double, 3> o = out(centroid);
        for (int k = 0; k < 3; ++k) {
            vn += n[k] * (double(a[3 + k]) + b[3 + k] + c[3 + k]);
            radial += n[k] * o[k];
        }
        if (!(vn > 0) || !(radial > 0)) ++bad;
    }
    return bad;
}

double enclosed_volume(const TriangleMesh& m) {
    double v = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const float* a = m.vertices.data() + 6 * m.indices[t];
        const float* b = m.vertices.data() + 6 * m.indices[t + 1];
        const float* c = m.vertices.data() + 6 * m.indices[t + 2];
        v += double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
             double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
             double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0]);
    }
    return v / 6;
}

bool same_bytes(const TriangleMesh& a, const TriangleMesh& b) {
    return a.vertices.size() == b.vertices.size() && a.indices.size() == b.indices.size() &&
           std::memcmp(a.vertices.data(), b.vertices.data(), a.vertices.size() * sizeof(float)) == 0 &&
           std::memcmp(a.indices.data(), b.indices.data(), a.indices.size() * sizeof(std::uint32_t)) == 0;
}

// Whether some vertex lies on a brick border plane (inside the lattice) of every axis.
bool crosses_brick_borders_on_every_axis(const TriangleMesh& m, const DensityGrid& g) {
    bool axis_hit[3] = {false, false, false};
    const float origin[3] = {g.ox, g.oy, g.oz};
    const std::uint32_t count[3] = {g.bx, g.by, g.bz};
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        for (int a = 0; a < 3; ++a)
            for (std::uint32_t b = 1; b < count[a]; ++b)
                if (m.vertices[6 * v + a] == origin[a] + g.voxel * float(b * kBrickCells)) axis_hit[a] = true;
    return axis_hit[0] && axis_hit[1] && axis_hit[2];
}

struct KernelBuffers {
    std::vector<float> vertices = std::vector<float>(6 * std::size_t(kBrickMaxVertices));
    std::vector<std::uint16_t> vertex_edge = std::vector<std::uint16_t>(kBrickMaxVertices);
    std::vector<std::uint16_t> edge_vertex = std::vector<std::uint16_t>(kBrickEdgeSlots);
    std::vector<std::uint16_t> triangles = std::vector<std::uint16_t>(3 * std::size_t(kBrickMaxTriangles));
    BrickMeshOut out() { return {vertices, vertex_edge, edge_vertex, triangles}; }
};

}  // namespace

TEST(VolumeMarchingCubes, BrickGivesOneVertexPerCrossedEdgeOwnedOnesFirst) {
    // Two bricks along x, a ball across their shared face: brick 0's vertices on that face belong to
    // brick 1 and come last, in edge order like the owned ones.
    DensityGrid g = grid_of(1, kVoxel);
    g.bx = 2;
    const Ball ball{{g.ox + 8.4 * kVoxel, g.oy + 4.3 * kVoxel, g.oz + 4.45 * kVoxel}, 4.8 * kVoxel};
    const Volume vol = make_volume(g, 0.5f, ball);
    ASSERT_EQ(vol.view().stored(), 2u);
    KernelBuffers kb;
    for (std::uint32_t slot = 0; slot < 2; ++slot) {
        std::fill(kb.edge_vertex.begin(), kb.edge_vertex.end(),
                  std::uint16_t(7));  // stale: must be rewritten
        const BrickMeshStats st = march_brick(vol.view(), slot, kb.out());
        const std::uint32_t a = vol.slot_brick[slot];
        std::uint32_t crossed = 0, on_max_face = 0, last_edge[2] = {0, 0};
        bool ordered = true;
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                for (std::uint32_t i = 0; i < kBrickEdge; ++i)
                    for (std::uint32_t axis = 0; axis < 3; ++axis) {
                        const std::uint32_t e = brick_edge_slot(i, j, k, axis);
                        const std::uint32_t c[3] = {i, j, k};
                        std::uint32_t hi[3] = {i, j, k};
                        ++hi[axis];
                        const bool inside_brick = c[axis] < kBrickCells;
                        const std::uint32_t gi = a * kBrickCells;
                        const bool cut =
                            inside_brick && (vol.view().sample(gi + i, j, k) >= 0.5f) !=
                                                (vol.view().sample(gi + hi[0], hi[1], hi[2]) >= 0.5f);
                        if (!cut) {
                            EXPECT_EQ(kb.edge_vertex[e], kNoVertex);
                            continue;
                        }
                        ++crossed;
                        const std::uint16_t vtx = kb.edge_vertex[e];
                        ASSERT_LT(vtx, st.vertices);
                        EXPECT_EQ(kb.vertex_edge[vtx], e);
                        const bool foreign = a == 0 && i == kBrickCells;  // brick 1 owns brick 0's max x face
                        on_max_face += foreign;
                        EXPECT_EQ(vtx >= st.owned, foreign);
                        const int group = foreign ? 1 : 0;
                        if (e < last_edge[group]) ordered = false;
                        last_edge[group] = e;
                    }
        EXPECT_EQ(st.vertices, crossed);
        EXPECT_EQ(st.vertices - st.owned, on_max_face);
        EXPECT_TRUE(ordered);
        if (a == 0) {
            EXPECT_GT(on_max_face, 0u) << "the ball crosses the shared face";
        }
        EXPECT_GT(st.triangles, 0u);
        for (std::uint32_t q = 0; q < 3 * st.triangles; ++q) ASSERT_LT(kb.triangles[q], st.vertices);
    }
    const TriangleMesh m = mesh_density_volume(vol.view());
    expect_same_triangles_as_plain_marching_cubes(vol, m);
    EXPECT_EQ(expect_watertight(m), 2);
}

TEST(VolumeMarchingCubes, BallMatchesPlainMarchingCubesAndIsWatertightAcrossBricks) {
    const DensityGrid g = grid_of(5, kVoxel);
    const Ball ball = ball_in(g);
    const Volume vol = make_volume(g, 0.5f, ball);
    EXPECT_LT(vol.view().stored(), g.bricks()) << "some bricks are F = 0 and not stored";
    const TriangleMesh m = mesh_density_volume(vol.view());
    expect_same_triangles_as_plain_marching_cubes(vol, m);
    EXPECT_TRUE(crosses_brick_borders_on_every_axis(m, g));
    EXPECT_EQ(expect_watertight(m), 2) << "a sphere";
}

TEST(VolumeMarchingCubes, BallVerticesLieOnTheSurfaceWithOutwardNormalsAndItsVolume) {
    const DensityGrid g = grid_of(5, kVoxel);
    const Ball ball = ball_in(g);
    const TriangleMesh m = mesh_density_volume(make_volume(g, 0.5f, ball).view());
    ASSERT_GT(m.triangle_count(), 1000u);
    const double r = ball.iso_radius();
    double worst_distance = 0, worst_dot = 1, worst_length = 0;
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const float* p = m.vertices.data() + 6 * v;
        const double d[3] = {p[0] - ball.c[0], p[1] - ball.c[1], p[2] - ball.c[2]};
        const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        worst_distance = std::max(worst_distance, std::abs(len - r));
        worst_dot = std::min(worst_dot, (d[0] * p[3] + d[1] * p[4] + d[2] * p[5]) / len);
        worst_length = std::max(
            worst_length,
            std::abs(std::sqrt(double(p[3]) * p[3] + double(p[4]) * p[4] + double(p[5]) * p[5]) - 1.0));
    }
    // Linear interpolation of a quadratic F errs by at most voxel^2 / (4 support^2) in F, i.e. 0.011 voxel
    // off the sphere here; central differences of a quadratic are exact, so normals are radial.
    EXPECT_LT(worst_distance, 0.015 * kVoxel);
    EXPECT_GT(worst_dot, 0.99999);
    EXPECT_LT(worst_length, 1e-6);
    EXPECT_EQ(count_misoriented(
                  m,
                  [&](const double* c) {
                      return std::array<double, 3>{c[0] - ball.c[0], c[1] - ball.c[1], c[2] - ball.c[2]};
                  }),
              0u);
    const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    // Vertices and chords both lie a little inside a convex surface: 0.6% short at 11 voxels' radius.
    EXPECT_NEAR(enclosed_volume(m), exact, 0.01 * exact);
    EXPECT_LT(enclosed_volume(m), exact);
}

TEST(VolumeMarchingCubes, ObliqueTorusIsClosedOrientedAndOnItsSurface) {
    const DensityGrid g = grid_of(4, 0.5f, 3.0f, -7.5f, 0.25f);
    const Torus torus = torus_in(g);
    const Volume vol = make_volume(g, 0.5f, torus);
    EXPECT_LT(vol.view().stored(), g.bricks());
    const TriangleMesh m = mesh_density_volume(vol.view());
    expect_same_triangles_as_plain_marching_cubes(vol, m);
    EXPECT_TRUE(crosses_brick_borders_on_every_axis(m, g));
    EXPECT_EQ(expect_watertight(m), 0) << "a torus";
    // Outward at a point: away from the nearest point of the core circle.
    const auto out = [&](const double* p) {
        const double d[3] = {p[0] - torus.c[0], p[1] - torus.c[1], p[2] - torus.c[2]};
        const double h = d[0] * torus.n[0] + d[1] * torus.n[1] + d[2] * torus.n[2];
        double radial[3], rl = 0;
        for (int k = 0; k < 3; ++k) radial[k] = d[k] - h * torus.n[k], rl += radial[k] * radial[k];
        rl = std::sqrt(rl);
        std::array<double, 3> o;
        for (int k = 0; k < 3; ++k) o[k] = d[k] - torus.major * radial[k] / rl;
        return o;
    };
    EXPECT_EQ(count_misoriented(m, out), 0u);
    double worst_distance = 0, worst_dot = 1;
    const double tube = torus.support / std::sqrt(2.0);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const float* p = m.vertices.data() + 6 * v;
        const double dp[3] = {p[0], p[1], p[2]};
        const std::array<double, 3> o = out(dp);
        const double len = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);
        worst_distance = std::max(worst_distance, std::abs(len - tube));
        worst_dot = std::min(worst_dot, (o[0] * p[3] + o[1] * p[4] + o[2] * p[5]) / len);
    }
    // F's error along an edge is at most voxel^2 / (4 support^2) as for the ball, 0.044 voxel off the
    // tube; central differences are no longer exact, but the normals stay close to the tube's.
    EXPECT_LT(worst_distance, 0.06 * g.voxel);
    EXPECT_GT(worst_dot, 0.98);
}

TEST(VolumeMarchingCubes, SameBytesAtAnyThreadCountAndSameTrianglesInAnySlotOrder) {
    const DensityGrid g = grid_of(8, 0.1f);
    const Ball ball{{g.ox + 31.3 * g.voxel, g.oy + 33.8 * g.voxel, g.oz + 32.4 * g.voxel}, 28.0 * g.voxel};
    const Volume vol = make_volume(g, 0.5f, ball);
    ASSERT_GT(vol.view().stored(), 100u);
    TriangleMesh one, many, two;
    tbb::task_arena(1).execute([&] { one = mesh_density_volume(vol.view()); });
    tbb::task_arena(2).execute([&] { two = mesh_density_volume(vol.view()); });
    many = mesh_density_volume(vol.view());
    ASSERT_GT(one.triangle_count(), 10000u);
    EXPECT_TRUE(same_bytes(one, many));
    EXPECT_TRUE(same_bytes(one, two));
    EXPECT_EQ(expect_watertight(one), 2);

    // Slots in reverse brick order: the same surface, listed in another order.
    const TriangleMesh reversed = mesh_density_volume(make_volume(g, 0.5f, ball, true).view());
    EXPECT_FALSE(same_bytes(one, reversed));
    EXPECT_EQ(test::canonical_triangles(reversed.vertices, 6, reversed.indices),
              test::canonical_triangles(one.vertices, 6, one.indices));
}

TEST(VolumeMarchingCubes, EmptyVolumesGiveEmptyMeshes) {
    const DensityGrid g = grid_of(3, kVoxel);
    const Volume none = make_volume(g, 0.5f, [](double, double, double) { return 0.0; });
    ASSERT_EQ(none.view().stored(), 0u);
    TriangleMesh m = mesh_density_volume(none.view());
    EXPECT_EQ(m.vertices.size(), 0u);
    EXPECT_EQ(m.indices.size(), 0u);

    // Stored bricks that never reach iso.
    const Ball faint = ball_in(g);
    const Volume low = make_volume(g, 2.0f, faint);
    ASSERT_GT(low.view().stored(), 0u);
    m = mesh_density_volume(low.view());
    EXPECT_EQ(m.vertices.size(), 0u);
    EXPECT_EQ(m.indices.size(), 0u);
}

TEST(VolumeMarchingCubes, RejectsIsoNotPositiveAndInconsistentViews) {
    const DensityGrid g = grid_of(3, kVoxel);
    Volume vol = make_volume(g, 0.5f, ball_in(g));
    for (const float iso : {0.0f, -1.0f, std::nanf("")}) {
        vol.iso = iso;
        EXPECT_THROW(mesh_density_volume(vol.view()), std::invalid_argument);
    }
    vol.iso = 0.5f;
    DensityVolumeView v = vol.view();
    v.brick_slot = v.brick_slot.first(v.brick_slot.size() - 1);
    EXPECT_THROW(mesh_density_volume(v), std::invalid_argument);
    vol.brick_slot[vol.slot_brick[0]] = -1;
    EXPECT_THROW(mesh_density_volume(vol.view()), std::invalid_argument);

    KernelBuffers kb;
    BrickMeshOut small = kb.out();
    small.triangles = small.triangles.first(10);
    EXPECT_THROW(march_brick(make_volume(g, 0.5f, ball_in(g)).view(), 0, small), std::invalid_argument);
}
