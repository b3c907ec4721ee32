// The hybrid method on a splash with a stream falling into it: the stream becomes one cylinder, the
// blob a watertight marching-slices mesh, the stream's end inside the blob's surface (the seam rule:
// particles near the blob are meshed by both), and the same bytes on 1 and 2 threads.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/hybrid_extractor.h"
#include "support/test_support.h"
#include "systems/scan/scan_mesh.h"

using namespace rivulet;
using namespace rivulet::test;

namespace {

constexpr float kRadius = 0.02f;
constexpr float kStreamTop = 0.9f;

// A ball of particles on a jittered lattice of spacing 2r (SPH-like) around (0, 0.2, 0), and a stream
// falling into it from kStreamTop: a particle on its axis and twelve on a circle of 0.025 every 1 cm.
PointCloud splash_with_stream() {
    PointCloud c;
    const float s = 2 * kRadius, ball = 0.16f;
    for (int i = -5; i <= 5; ++i)
        for (int j = -5; j <= 5; ++j)
            for (int k = -5; k <= 5; ++k) {
                const float x = float(i) * s, y = float(j) * s, z = float(k) * s;
                if (x * x + y * y + z * z > ball * ball) continue;
                const float jitter = 0.1f * s * std::sin(float(i * 7 + j * 13 + k * 29));
                c.add(x + jitter, 0.2f + y - jitter, z + 0.5f * jitter);
            }
    for (float y = 0.2f + ball; y <= kStreamTop; y += 0.01f) {
        c.add(0.0f, y, 0.0f);
        for (int k = 0; k < 12; ++k) {
            const float a = 2 * std::numbers::pi_v<float> * (float(k) + 37 * y) / 12;
            c.add(0.025f * std::cos(a), y, 0.025f * std::sin(a));
        }
    }
    return c;
}

struct Hybrid {
    ScanOutput cylinders;
    SurfaceMesh mesh;
    TriangleMesh tubes;
    std::uint64_t hash = 0;
};

Hybrid extract(const PointCloud& c, int threads) {
    ScanSettings scan;
    scan.radius = kRadius;
    scan.fit_v_range(c.y);
    SlicesSettings slices;
    slices.radius = kRadius;
    HybridExtractor hybrid(scan, slices, c.size());
    Hybrid h;
    hybrid.prepare_output(h.cylinders);
    FrameGraph graph;
    hybrid.add_jobs(
        graph, [&c] { return c.pos(); }, [&h]() -> ScanOutput& { return h.cylinders; },
        [&h]() -> SurfaceMesh& { return h.mesh; });
    tbb::task_arena arena(threads);
    arena.execute([&] { graph.run(); });
    h.tubes = assemble_scan_mesh(h.cylinders, hybrid.scan().layout(), kRadius);
    h.hash = mesh_hash(h.tubes) ^ (mesh_hash(h.mesh.view()) * 31);
    return h;
}

// Generalised winding number of a closed mesh at q (1 inside, 0 outside), by solid angles.
double winding_number(const TriangleMeshView& m, const float* q) {
    double sum = 0;
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        double a[3], b[3], c[3];
        for (int k = 0; k < 3; ++k) {
            a[k] = m.vertices[6 * m.indices[t] + k] - q[k];
            b[k] = m.vertices[6 * m.indices[t + 1] + k] - q[k];
            c[k] = m.vertices[6 * m.indices[t + 2] + k] - q[k];
        }
        const double la = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        const double lb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
        const double lc = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
        const double det = a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                           a[2] * (b[0] * c[1] - b[1] * c[0]);
        const double dot_ab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        const double dot_bc = b[0] * c[0] + b[1] * c[1] + b[2] * c[2];
        const double dot_ca = c[0] * a[0] + c[1] * a[1] + c[2] * a[2];
        sum += 2 * std::atan2(det, la * lb * lc + dot_ab * lc + dot_bc * la + dot_ca * lb);
    }
    return sum / (4 * std::numbers::pi);
}

TEST(HybridMethod, StreamIsACylinderTheBlobSlicesAndTheSeamIsInside) {
    const PointCloud c = splash_with_stream();
    const Hybrid h = extract(c, 2);
    ASSERT_EQ(h.cylinders.draw_count, 1u) << "the stream, and nothing else, as a cylinder";
    EXPECT_EQ(h.cylinders.sphere_count, 0u);
    const TriangleMeshView blob = h.mesh.view();
    ASSERT_GT(blob.indices.size(), 0u);
    // Both surfaces closed.
    EXPECT_EQ(count_open_edges(strided_positions(h.tubes.vertices, 6), h.tubes.indices), 0u);
    EXPECT_EQ(count_open_edges(strided_positions(blob.vertices, 6), blob.indices, 1e-6f), 0u);
    // The blob's mesh covers the ball and not the stream's upper part.
    float top = -1e9f;
    for (std::size_t v = 0; v < blob.vertices.size(); v += 6) top = std::max(top, blob.vertices[v + 1]);
    EXPECT_GT(top, 0.2f + 0.16f);
    EXPECT_LT(top, kStreamTop - 0.2f);
    // The seam: the tube's lower end (its pole and last ring, the lowest vertices of the tube) lies inside
    // the blob's surface, so no gap opens between them.
    const GroupDraw d = h.cylinders.draws[0];
    const CylinderLayout layout{20, ScanSettings{}.v};
    const float* verts =
        h.cylinders.vertices.data() + std::size_t(d.cylinder) * layout.verts_per_cylinder() * 6;
    const float* a = verts + 6 * std::size_t(layout.top_pole(d.vmin));
    const float* b = verts + 6 * std::size_t(layout.bottom_pole(d.vmax));
    const bool low_is_last = b[1] < a[1];
    const std::uint32_t end_ring = low_is_last ? d.vmax : d.vmin;
    const float* pole = low_is_last ? b : a;
    EXPECT_GT(winding_number(blob, pole), 0.5) << "the stream's end cap sticks out of the blob";
    for (std::uint32_t k = 0; k < layout.u; ++k)
        EXPECT_GT(winding_number(blob, verts + 6 * std::size_t(layout.side_vertex(end_ring, k))), 0.5)
            << "end ring vertex " << k;
    // The tube's top is the stream's top, not swallowed.
    EXPECT_GT(std::max(a[1], b[1]), kStreamTop);
}

TEST(HybridMethod, SameBytesOnOneAndTwoThreads) {
    const PointCloud c = splash_with_stream();
    EXPECT_EQ(extract(c, 1).hash, extract(c, 2).hash);
}

}  // namespace
