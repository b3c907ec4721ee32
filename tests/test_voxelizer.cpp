// Diffuse objects' voxel space ("Rendering diffuse objects using particle systems inside voxelized surface
// geometry", Juckel & Beckhaus, §4.2): procedural meshes, Assimp input and the parity voxelizer.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>

#include "support/test_support.h"
#include "systems/diffuse/procedural_meshes.h"
#include "systems/diffuse/voxelizer.h"
#include "systems/io/assimp_mesh.h"

using namespace rivulet;

namespace {

constexpr double kPi = std::numbers::pi;

// Signed volume by the divergence theorem: positive for a closed, outward-wound mesh.
double mesh_volume(const ColoredMesh& m) {
    double v = 0;
    for (std::size_t t = 0; t < m.triangle_count(); ++t) {
        const float* a = &m.positions[3 * m.indices[3 * t]];
        const float* b = &m.positions[3 * m.indices[3 * t + 1]];
        const float* c = &m.positions[3 * m.indices[3 * t + 2]];
        v += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
              double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
              double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
             6;
    }
    return v;
}

double voxel_volume(const SolidVoxels& s) {
    return double(s.inside_count()) * std::pow(double(s.shape.cell), 3);
}

void append(ColoredMesh& to, const ColoredMesh& from) {
    const auto base = static_cast<std::uint32_t>(to.vertex_count());
    to.positions.insert(to.positions.end(), from.positions.begin(), from.positions.end());
    to.colors.insert(to.colors.end(), from.colors.begin(), from.colors.end());
    for (std::uint32_t i : from.indices) to.indices.push_back(base + i);
}

void drop_triangles(ColoredMesh& m, std::size_t first, std::size_t count) {
    m.indices.erase(m.indices.begin() + 3 * first, m.indices.begin() + 3 * (first + count));
}

void paint(ColoredMesh& m, float r, float g, float b) {
    m.colors.clear();
    for (std::size_t v = 0; v < m.vertex_count(); ++v) m.colors.insert(m.colors.end(), {r, g, b});
}

std::string bunny_path() {
    return std::string(RIVULET_SOURCE_DIR) + "/data/bunny.ply";
}

}  // namespace

TEST(ProceduralMeshes, ClosedAndOutward) {
    const ColoredMesh meshes[] = {make_uv_sphere({1, 2, 3}, 0.5f, 16, 8),
                                  make_torus({0, 0, 0}, 1, 0.3f, 24, 12),
                                  make_box_mesh({-1, 0, 2}, {1, 3, 2.5f}), make_ghost_mesh()};
    for (const ColoredMesh& m : meshes) {
        EXPECT_EQ(test::count_open_edges(m.positions, m.indices), 0u);
        EXPECT_GT(mesh_volume(m), 0.0);
    }
    EXPECT_NEAR(mesh_volume(meshes[2]), 2 * 3 * 0.5, 1e-6);
    EXPECT_THROW(make_uv_sphere({0, 0, 0}, 1, 2, 8), std::invalid_argument);
    EXPECT_THROW(make_torus({0, 0, 0}, 1, 2, 8, 8), std::invalid_argument);
    EXPECT_THROW(make_box_mesh({0, 0, 0}, {1, 0, 1}), std::invalid_argument);
}

TEST(ProceduralMeshes, GhostShape) {
    const ColoredMesh g = make_ghost_mesh();
    EXPECT_LT(g.triangle_count(), 20000u);
    ASSERT_EQ(g.colors.size(), g.positions.size());
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (std::size_t v = 0; v < g.vertex_count(); ++v)
        for (int a = 0; a < 3; ++a)
            lo[a] = std::min(lo[a], g.positions[3 * v + a]), hi[a] = std::max(hi[a], g.positions[3 * v + a]);
    EXPECT_NEAR(lo[1], 0.0f, 1e-6f);
    EXPECT_NEAR(hi[1], 1.6f, 1e-5f);
    EXPECT_NEAR(lo[0] + hi[0], 0.0f, 0.01f);  // the wavy hem is not quite symmetric
    EXPECT_NEAR(lo[2] + hi[2], 0.0f, 0.01f);
    // Dark eye vertices on the front (+z) of the head, none at the back.
    std::size_t front = 0, back = 0;
    for (std::size_t v = 0; v < g.vertex_count(); ++v)
        if (g.colors[3 * v + 2] < 0.2f) (g.positions[3 * v + 2] > 0 ? front : back) += 1;
    EXPECT_GT(front, 20u);
    EXPECT_EQ(back, 0u);
}

TEST(Voxelizer, SphereVolume) {
    const ColoredMesh m = make_uv_sphere({0.3f, -0.2f, 0.1f}, 1.0f, 256, 128);
    const SolidVoxels s = voxelize(m, 128);
    EXPECT_EQ(s.shape.nx, 130);
    const double exact = 4.0 / 3.0 * kPi, tess = mesh_volume(m);
    EXPECT_NEAR(tess, exact, 0.002 * exact);
    EXPECT_NEAR(voxel_volume(s), exact, 0.02 * exact);
    EXPECT_NEAR(voxel_volume(s), tess, 0.01 * tess);
}

TEST(Voxelizer, TorusVolume) {
    const ColoredMesh m = make_torus({0, 0.5f, 0}, 1.0f, 0.4f, 256, 128);
    const SolidVoxels s = voxelize(m, 128);
    const double exact = 2 * kPi * kPi * 1.0 * 0.4 * 0.4, tess = mesh_volume(m);
    EXPECT_NEAR(tess, exact, 0.002 * exact);
    EXPECT_NEAR(voxel_volume(s), exact, 0.02 * exact);
    // The hole stays empty: the voxel at the centre of the grid.
    EXPECT_EQ(s.inside[s.shape.index(s.shape.nx / 2, s.shape.ny / 2, s.shape.nz / 2)], 0);
}

// Box B's faces, edges, corners and face diagonals lie exactly on voxel centres, so most of its columns
// pass through shared edges or vertices; two unit boxes at the corners of [0, 16]^3 fix the grid to unit
// cells with centres at k + 0.5. A centre on the surface counts as displaced towards (+x, +y, +z), so
// the voxels on B's -x, -y, -z faces are inside and those on its +x, +y, +z faces are not: 8^3, exactly.
TEST(Voxelizer, ExactOnSharedEdgesAndVertices) {
    ColoredMesh m = make_box_mesh({0, 0, 0}, {1, 1, 1});
    append(m, make_box_mesh({15, 15, 15}, {16, 16, 16}));
    append(m, make_box_mesh({2.5f, 2.5f, 2.5f}, {10.5f, 10.5f, 10.5f}));
    const SolidVoxels s = voxelize(m, 16, 1);
    ASSERT_EQ(s.shape.nx, 18);
    ASSERT_EQ(s.shape.cell, 1.0f);
    EXPECT_EQ(s.inside_count(), 2u + 512u);
    for (int iz = 0; iz < s.shape.nz; ++iz)
        for (int iy = 0; iy < s.shape.ny; ++iy)
            for (int ix = 0; ix < s.shape.nx; ++ix) {
                const Vec3f c = s.shape.centre(ix, iy, iz);
                auto in = [](float v, float lo, float hi) { return v >= lo && v < hi; };
                const bool inside_b = in(c.x, 2.5f, 10.5f) && in(c.y, 2.5f, 10.5f) && in(c.z, 2.5f, 10.5f);
                const bool corner = (in(c.x, 0, 1) && in(c.y, 0, 1) && in(c.z, 0, 1)) ||
                                    (in(c.x, 15, 16) && in(c.y, 15, 16) && in(c.z, 15, 16));
                ASSERT_EQ(s.inside[s.shape.index(ix, iy, iz)], inside_b || corner ? 1 : 0)
                    << ix << " " << iy << " " << iz;
            }
}

// A shell inside another carves a cavity.
TEST(Voxelizer, NestedShellIsHollow) {
    ColoredMesh m = make_box_mesh({0, 0, 0}, {10, 10, 10});
    append(m, make_box_mesh({3, 3, 3}, {7, 7, 7}));
    const SolidVoxels s = voxelize(m, 10, 0);
    EXPECT_EQ(s.inside_count(), 1000u - 64u);
    EXPECT_EQ(s.inside[s.shape.index(5, 5, 5)], 0);
}

TEST(Voxelizer, SameBytesAtOneAndTwoThreads) {
    ColoredMesh m = make_ghost_mesh();
    auto run = [&](int threads) {
        tbb::task_arena arena(threads);
        return arena.execute([&] { return voxelize(m, 96, 2); });
    };
    const SolidVoxels a = run(1), b = run(2);
    EXPECT_GT(a.inside_count(), 1000u);
    EXPECT_EQ(a.inside, b.inside);
    EXPECT_EQ(a.r, b.r);
    EXPECT_EQ(a.g, b.g);
    EXPECT_EQ(a.b, b.b);
}

TEST(Voxelizer, OpenMeshThrows) {
    ColoredMesh m = make_box_mesh({0, 0, 0}, {1, 1, 1});
    drop_triangles(m, 10, 2);  // the +z face
    try {
        voxelize(m, 8);
        FAIL() << "an open box was voxelized";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("not closed: 4 edges bound a hole"), std::string::npos)
            << e.what();
    }
}

TEST(Voxelizer, RejectsBadInput) {
    const ColoredMesh box = make_box_mesh({0, 0, 0}, {1, 1, 1});
    EXPECT_THROW(voxelize(box, 0), std::invalid_argument);
    EXPECT_THROW(voxelize(box, 257), std::invalid_argument);
    EXPECT_THROW(voxelize(box, 8, -1), std::invalid_argument);
    EXPECT_THROW(voxelize(ColoredMesh{}, 8), std::invalid_argument);
    ColoredMesh bad = box;
    bad.positions[4] = std::nanf("");
    EXPECT_THROW(voxelize(bad, 8), std::invalid_argument);
    bad = box;
    bad.indices[5] = 8;
    EXPECT_THROW(voxelize(bad, 8), std::invalid_argument);
    bad = box;
    bad.colors = {1, 0, 0};
    EXPECT_THROW(voxelize(bad, 8), std::invalid_argument);
    ColoredMesh flat = box;
    for (std::size_t v = 0; v < flat.vertex_count(); ++v)
        flat.positions[3 * v] = flat.positions[3 * v + 1] = 0.5f;
    flat.positions = std::vector<float>(flat.positions.size(), 0.5f);
    EXPECT_THROW(voxelize(flat, 8), std::invalid_argument);
}

TEST(Voxelizer, WhiteWithoutColours) {
    const SolidVoxels s = voxelize(make_box_mesh({0, 0, 0}, {1, 1, 1}), 8);
    for (std::size_t v = 0; v < s.inside.size(); ++v) {
        EXPECT_EQ(s.r[v], s.inside[v] ? 1.0f : 0.0f);
        EXPECT_EQ(s.b[v], s.inside[v] ? 1.0f : 0.0f);
    }
}

// Two half boxes, red (x < 0) and blue (x > 0), without the faces at x = 0: closed once the duplicated
// seam vertices are welded. Every inside voxel takes the colour of the half it is in, deep ones too.
TEST(Voxelizer, NearestSurfaceColour) {
    ColoredMesh left = make_box_mesh({-1, -0.25f, -0.25f}, {0, 0.25f, 0.25f});
    ColoredMesh right = make_box_mesh({0, -0.25f, -0.25f}, {1, 0.25f, 0.25f});
    drop_triangles(left, 2, 2);   // its +x face
    drop_triangles(right, 0, 2);  // its -x face
    paint(left, 1, 0, 0);
    paint(right, 0, 0, 1);
    ColoredMesh m = left;
    append(m, right);
    const SolidVoxels s = voxelize(m, 64);
    EXPECT_EQ(s.inside_count(), 64u * 16 * 16);
    for (int iz = 0; iz < s.shape.nz; ++iz)
        for (int iy = 0; iy < s.shape.ny; ++iy)
            for (int ix = 0; ix < s.shape.nx; ++ix) {
                const std::size_t v = s.shape.index(ix, iy, iz);
                if (!s.inside[v]) {
                    ASSERT_EQ(s.r[v] + s.g[v] + s.b[v], 0.0f);
                    continue;
                }
                const bool red = s.shape.centre(ix, iy, iz).x < 0;
                ASSERT_EQ(s.r[v], red ? 1.0f : 0.0f) << ix << " " << iy << " " << iz;
                ASSERT_EQ(s.b[v], red ? 0.0f : 1.0f) << ix << " " << iy << " " << iz;
            }
}

TEST(AssimpMesh, ReadsObjAndPlyWithVertexColours) {
    const std::string obj = test::temp_path("voxelizer_tetra.obj");
    test::write_text(obj,
                     "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 1\nv 0 0 1 1 1 1\n"
                     "f 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    const ColoredMesh a = read_colored_mesh(obj);
    EXPECT_EQ(a.triangle_count(), 4u);
    ASSERT_EQ(a.colors.size(), a.positions.size());
    for (std::size_t v = 0; v < a.vertex_count(); ++v)  // the vertex at x = 1 is green
        if (a.positions[3 * v] == 1.0f) {
            EXPECT_EQ(a.colors[3 * v + 1], 1.0f);
        }
    EXPECT_NEAR(std::abs(mesh_volume(a)), 1.0 / 6, 1e-6);
    EXPECT_NO_THROW(voxelize(a, 16));

    const std::string ply = test::temp_path("voxelizer_quad.ply");
    test::write_text(ply,
                     "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
                     "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
                     "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                     "0 0 0 255 0 0\n2 0 0 255 0 0\n2 1 0 0 0 255\n0 1 0 0 0 255\n4 0 1 2 3\n");
    const ColoredMesh b = read_colored_mesh(ply);
    EXPECT_EQ(b.triangle_count(), 2u);  // the quad, triangulated
    ASSERT_EQ(b.colors.size(), b.positions.size());
    for (std::size_t v = 0; v < b.vertex_count(); ++v) {
        EXPECT_EQ(b.colors[3 * v], b.positions[3 * v + 1] == 0 ? 1.0f : 0.0f);
        EXPECT_EQ(b.colors[3 * v + 2], b.positions[3 * v + 1] == 0 ? 0.0f : 1.0f);
    }
}

TEST(AssimpMesh, NoColoursWhenTheFileHasNone) {
    const std::string obj = test::temp_path("voxelizer_plain.obj");
    test::write_text(obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
    EXPECT_TRUE(read_colored_mesh(obj).colors.empty());
    const std::string ply = test::temp_path("voxelizer_plain.ply");
    test::write_text(ply,
                     "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                     "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                     "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    const ColoredMesh p = read_colored_mesh(ply);
    EXPECT_EQ(p.triangle_count(), 1u);
    EXPECT_TRUE(p.colors.empty());
}

TEST(AssimpMesh, ThrowsOnMissingOrGarbageFiles) {
    const std::string missing = test::temp_path("voxelizer_missing.obj");
    try {
        read_colored_mesh(missing);
        FAIL();
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find(missing), std::string::npos) << e.what();
    }
    const std::string garbage = test::temp_path("voxelizer_garbage.ply");
    test::write_text(garbage,
                     "ply\nformat binary_little_endian 1.0\nelement vertex 99999999\nend_header\n\x01\x02");
    EXPECT_THROW(read_colored_mesh(garbage), std::runtime_error);
    const std::string noise = test::temp_path("voxelizer_noise.glb");
    test::write_text(noise, std::string(200, '\x7f'));
    EXPECT_THROW(read_colored_mesh(noise), std::runtime_error);
    const std::string lines = test::temp_path("voxelizer_lines.obj");
    test::write_text(lines, "v 0 0 0\nv 1 0 0\nv 0 1 0\nl 1 2 3\n");
    EXPECT_THROW(read_colored_mesh(lines), std::runtime_error);
}

TEST(Bunny, LoadsClosedAndVoxelizes) {
    const ColoredMesh m = read_colored_mesh(bunny_path());
    EXPECT_GT(m.triangle_count(), 3000u);
    ASSERT_EQ(m.colors.size(), m.positions.size());
    EXPECT_EQ(test::count_open_edges(m.positions, m.indices), 0u);
    const double volume = mesh_volume(m);
    EXPECT_GT(volume, 0.0);
    const SolidVoxels s = voxelize(m, 50);
    EXPECT_NEAR(float(s.shape.ny) * s.shape.cell, 0.5f + 2 * s.shape.cell, 0.02f);  // about 0.5 tall
    EXPECT_NEAR(voxel_volume(s), volume, 0.08 * volume);
    std::size_t red = 0, white = 0;
    for (std::size_t v = 0; v < s.inside.size(); ++v) {
        red += s.inside[v] && s.r[v] > 0.7f && s.g[v] < 0.4f;
        white += s.inside[v] && s.r[v] > 0.9f && s.g[v] > 0.9f;
    }
    EXPECT_GT(red, 10u);
    EXPECT_GT(white, 0u);
}

// Not a check: prints voxelize timings (run with --gtest_also_run_disabled_tests).
TEST(Voxelizer, DISABLED_Timings) {
    const ColoredMesh meshes[] = {read_colored_mesh(bunny_path()), make_ghost_mesh()};
    const char* names[] = {"bunny", "ghost"};
    for (int k = 0; k < 2; ++k)
        for (int res : {50, 128, 256}) {
            voxelize(meshes[k], res);
            const auto t0 = std::chrono::steady_clock::now();
            const SolidVoxels s = voxelize(meshes[k], res);
            const double ms =
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
            std::printf("%s %d^3 (%dx%dx%d): %.1f ms, %zu inside\n", names[k], res, s.shape.nx, s.shape.ny,
                        s.shape.nz, ms, s.inside_count());
        }
}
