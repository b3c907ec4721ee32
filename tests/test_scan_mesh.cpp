// Meshes from sphere scan conversion: closed, unit normals pointing outward, and the right size.
#include <gtest/gtest.h>

#include <cmath>

#include "support/test_support.h"
#include "systems/particles/particle_set.h"
#include "systems/scan/scan_converter.h"
#include "systems/scan/scan_mesh.h"
#include "systems/scenes/scene.h"
#include "systems/sim/stream_sim.h"

using namespace rivulet;

namespace {

struct Extracted {
    ScanOutput out;
    TriangleMesh mesh;
    std::uint32_t groups = 0;
};

Extracted extract(const ParticleSet& p, const ScanSettings& s) {
    ScanConverter scan(s, p.size());
    Extracted e;
    scan.prepare_output(e.out);
    scan.extract_serial(p.positions(), e.out);
    e.mesh = assemble_scan_mesh(e.out, scan.layout(), s.radius);
    e.groups = scan.groups();
    return e;
}

std::vector<float> positions_of(const TriangleMesh& m) {
    std::vector<float> p;
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
        p.insert(p.end(), &m.vertices[6 * v], &m.vertices[6 * v + 3]);
    return p;
}

// Signed volume (divergence theorem): positive when the closed surface's triangles wind outward.
double signed_volume(const TriangleMesh& m, std::size_t first_index, std::size_t end_index) {
    double vol = 0;
    for (std::size_t t = first_index; t < end_index; t += 3) {
        const float* a = &m.vertices[6 * m.indices[t]];
        const float* b = &m.vertices[6 * m.indices[t + 1]];
        const float* c = &m.vertices[6 * m.indices[t + 2]];
        vol += (a[0] * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
                a[1] * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
                a[2] * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
               6.0;
    }
    return vol;
}

void expect_unit_normals(const TriangleMesh& m) {
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
        const float* n = &m.vertices[6 * v + 3];
        ASSERT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-4) << "vertex " << v;
    }
}

// A vertical column of 81 spheres of radius 0.05 around the axis x = 0.3, z = -0.1, y in [0.2, 1.0].
ParticleSet column_of_spheres() {
    ParticleSet p(200);
    for (int i = 0; i <= 80; ++i)
        p.push(0.3f, 0.2f + 0.01f * static_cast<float>(i), -0.1f, 0, 0, 0, static_cast<std::uint32_t>(i));
    return p;
}

ScanSettings column_settings(RadialFunction function) {
    ScanSettings s;
    s.radius = 0.05f, s.u = 20, s.v = 61, s.v_top = 1.2f, s.v_bottom = 0.0f;
    s.section.function = function;
    return s;
}

}  // namespace

TEST(ScanMesh, VerticalColumnGivesAClosedTubeOfTheSphereRadiusWithOutwardNormals) {
    const Extracted e = extract(column_of_spheres(), column_settings(RadialFunction::kCircleMaxima));
    ASSERT_EQ(e.groups, 1u);
    EXPECT_EQ(e.out.sphere_count, 0u);
    EXPECT_EQ(rivulet::test::count_open_edges(positions_of(e.mesh), e.mesh.indices), 0u);
    expect_unit_normals(e.mesh);
    EXPECT_GT(signed_volume(e.mesh, 0, e.mesh.indices.size()), 0.0);
    // Away from the ends every plane is cut by a sphere through its centre: radius = sphere radius.
    int checked = 0;
    for (std::size_t v = 0; v < e.mesh.vertex_count(); ++v) {
        const float* q = &e.mesh.vertices[6 * v];
        if (q[1] < 0.3f || q[1] > 0.9f) continue;
        const float dx = q[0] - 0.3f, dz = q[2] + 0.1f;
        EXPECT_NEAR(std::sqrt(dx * dx + dz * dz), 0.05f, 0.05f * 0.02f);
        EXPECT_GT((q[3] * dx + q[5] * dz) / std::sqrt(dx * dx + dz * dz), 0.95f)
            << "normal not outward at " << v;
        ++checked;
    }
    EXPECT_GT(checked, 100);
}

TEST(ScanMesh, BlendedGaussiansGiveAClosedTubeInsideTheSpheres) {
    const Extracted e = extract(column_of_spheres(), column_settings(RadialFunction::kGaussianBlend));
    ASSERT_EQ(e.groups, 1u);
    EXPECT_EQ(rivulet::test::count_open_edges(positions_of(e.mesh), e.mesh.indices), 0u);
    expect_unit_normals(e.mesh);
    EXPECT_GT(signed_volume(e.mesh, 0, e.mesh.indices.size()), 0.0);
    for (std::size_t v = 0; v < e.mesh.vertex_count(); ++v) {
        const float* q = &e.mesh.vertices[6 * v];
        const float dx = q[0] - 0.3f, dz = q[2] + 0.1f;
        EXPECT_LE(std::sqrt(dx * dx + dz * dz), 0.05f * 1.0001f) << "beyond the spheres at vertex " << v;
    }
}

TEST(ScanMesh, FountainFrameIsClosedWithUnitNormalsAndOutwardCylinders) {
    const SceneDesc scene = make_builtin_scene("fountain");
    StreamSimulation sim(scene);
    ParticleSet p(scene.max_particles);
    for (std::uint64_t f = 0; f < 150; ++f) sim.step_serial(p, f);
    ScanSettings s;
    s.radius = scene.particle_radius, s.v_top = scene.v_max, s.v_bottom = scene.v_min;
    const Extracted e = extract(p, s);
    ASSERT_GT(e.groups, 5u);
    EXPECT_EQ(rivulet::test::count_open_edges(positions_of(e.mesh), e.mesh.indices), 0u);
    expect_unit_normals(e.mesh);
    // Each cylinder is its own closed piece: check its orientation separately.
    std::size_t index = 0;
    for (const GroupDraw& d : e.out.draws.span(e.out.draw_count)) {
        const std::size_t count = 3 * (2ull * s.u * (d.vmax - d.vmin) + 2ull * s.u);
        EXPECT_GT(signed_volume(e.mesh, index, index + count), 0.0) << "cylinder " << d.cylinder;
        index += count;
    }
    if (e.out.sphere_count > 0) {
        EXPECT_GT(signed_volume(e.mesh, index, e.mesh.indices.size()), 0.0) << "isolated spheres";
    }
}

TEST(ScanMesh, MeshHashDependsOnEveryByte) {
    ParticleSet p(10);
    for (int i = 0; i < 5; ++i)
        p.push(0, 0.5f + 0.03f * static_cast<float>(i), 0, 0, 0, 0, static_cast<std::uint32_t>(i));
    ScanSettings s;
    s.radius = 0.03f, s.v = 30, s.v_top = 1, s.v_bottom = 0;
    Extracted e = extract(p, s);
    const std::uint64_t h = mesh_hash(e.mesh);
    EXPECT_EQ(h, mesh_hash(extract(p, s).mesh));
    e.mesh.vertices[7] = std::nextafter(e.mesh.vertices[7], 1.0f);
    EXPECT_NE(h, mesh_hash(e.mesh));
}
