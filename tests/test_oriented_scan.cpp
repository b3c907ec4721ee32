// Scan conversion with cylinders along the stream's path: a horizontal hose and a parabolic arc of
// particles with a known circular cross-section come out as one round tube of the stream's radius along
// their whole length (the V-axis cylinders spread the arc's top over its horizontal run), closed, with each
// ring's radii those of every sphere that cuts its plane, and the same bytes on 1 and 2 threads.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>

#include "jobs/cross_section.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/scan_jobs.h"
#include "support/test_support.h"
#include "systems/scan/oriented_scan.h"
#include "systems/scan/scan_converter.h"
#include "systems/scan/scan_mesh.h"

using namespace rivulet;
using namespace rivulet::test;

namespace {

constexpr float kRadius = 0.02f;  // sphere radius
constexpr float kCore = 0.03f;    // radius of the circle the particles sit on in each cross-section
constexpr float kTube = kCore + kRadius;

struct Centreline {
    std::function<void(float, float*, float*)> at;  // s -> point, unit tangent
    float length = 0;
};

// Cross-sections every 1 cm along the centreline: a particle on it and twelve on a circle of radius
// kCore around it in the normal plane, turned a little from section to section.
PointCloud stream(const Centreline& line) {
    PointCloud c;
    for (float s = 0; s <= line.length + 1e-6f; s += 0.01f) {
        float p[3], t[3];
        line.at(s, p, t);
        // Normal plane basis: n = t x z (t never along z here), b = t x n.
        float n[3] = {t[1], -t[0], 0};
        const float ln = std::hypot(n[0], n[1]);
        n[0] /= ln, n[1] /= ln;
        const float b[3] = {t[1] * n[2] - t[2] * n[1], t[2] * n[0] - t[0] * n[2], t[0] * n[1] - t[1] * n[0]};
        c.add(p[0], p[1], p[2]);
        for (int k = 0; k < 12; ++k) {
            const float a = 2 * std::numbers::pi_v<float> * (float(k) + 0.37f * s / 0.01f) / 12;
            const float ca = kCore * std::cos(a), sa = kCore * std::sin(a);
            c.add(p[0] + ca * n[0] + sa * b[0], p[1] + ca * n[1] + sa * b[1], p[2] + ca * n[2] + sa * b[2]);
        }
    }
    return c;
}

Centreline hose() {
    return {[](float s, float* p, float* t) {
                p[0] = s, p[1] = 0.5f, p[2] = 0.2f;
                t[0] = 1, t[1] = 0, t[2] = 0;
            },
            2.0f};
}

// y = 1 - x^2 / 2 for x in [-1, 1], by arc length (tabulated).
Centreline arc() {
    auto point = [](float x, float* p) { p[0] = x, p[1] = 1.0f - 0.5f * x * x, p[2] = 0.0f; };
    auto table = std::make_shared<std::vector<float>>();  // x at every 1 mm of arc length
    double x = -1.0, walked = 0.0, next = 0.0;
    while (x <= 1.0) {
        if (walked >= next) table->push_back(float(x)), next += 0.001;
        const double dx = 1e-5;
        walked += dx * std::sqrt(1.0 + x * x);
        x += dx;
    }
    const float length = 0.001f * float(table->size() - 1);
    return {[table, point](float s, float* p, float* t) {
                const auto i = std::min<std::size_t>(std::size_t(std::lround(s / 0.001f)), table->size() - 1);
                const float xi = (*table)[i];
                point(xi, p);
                const float l = std::sqrt(1.0f + xi * xi);
                t[0] = 1.0f / l, t[1] = -xi / l, t[2] = 0.0f;
            },
            length};
}

ScanSettings settings() {
    ScanSettings s;
    s.radius = kRadius;
    s.axis = CylinderAxis::kPath;
    s.v = 240;
    return s;
}

struct Tube {
    ScanOutput out;
    TriangleMesh mesh;
};

Tube extract(const PointCloud& c, int threads = 0) {
    OrientedScan scan(settings(), c.size());
    Tube t;
    scan.prepare_output(t.out);
    if (threads == 0) {
        scan.extract_serial(c.pos(), t.out);
    } else {
        FrameGraph graph;
        add_oriented_scan_jobs(
            graph, scan, [&c] { return c.pos(); }, [&t]() -> ScanOutput& { return t.out; });
        tbb::task_arena arena(threads);
        arena.execute([&] { graph.run(); });
    }
    t.mesh = assemble_scan_mesh(t.out, scan.layout(), kRadius);
    return t;
}

// Distance from q to the centreline (sampled every millimetre) and the arc length of the nearest sample.
float distance_to(const Centreline& line, const float* q, float& at) {
    float best = 1e9f;
    for (float s = 0; s <= line.length; s += 0.001f) {
        float p[3], t[3];
        line.at(s, p, t);
        const float d = std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
        if (d < best) best = d, at = s;
    }
    return best;
}

// Every ring farther than two sphere radii from the stream's ends: its mean distance from the centreline
// within 10 % of the stream's radius, and no vertex off by more than 25 %.
void expect_round_tube(const Centreline& line, const Tube& t, std::uint32_t u) {
    ASSERT_EQ(t.out.draw_count, 1u) << "one stream, one cylinder: no cap inside it";
    EXPECT_EQ(t.out.sphere_count, 0u);
    const GroupDraw d = t.out.draws[0];
    const CylinderLayout layout{u, settings().v};
    int checked = 0;
    for (std::uint32_t r = d.vmin; r <= d.vmax; ++r) {
        double sum = 0;
        float worst = 0, at = 0;
        for (std::uint32_t k = 0; k < u; ++k) {
            const float* v = t.out.vertices.data() + 6 * std::size_t(layout.side_vertex(r, k));
            const float dist = distance_to(line, v, at);
            sum += dist;
            worst = std::max(worst, std::abs(dist - kTube));
        }
        if (at < 2 * kRadius || at > line.length - 2 * kRadius) continue;
        ++checked;
        EXPECT_NEAR(sum / u, kTube, 0.10 * kTube) << "ring " << r << " at arc length " << at;
        EXPECT_LT(worst, 0.25f * kTube) << "ring " << r << " at arc length " << at;
    }
    EXPECT_GT(checked, 20);
    // The caps close the tube about one sphere radius past the end particles.
    for (const std::uint32_t pole : {layout.top_pole(d.vmin), layout.bottom_pole(d.vmax)}) {
        float at = 0;
        const float* v = t.out.vertices.data() + 6 * std::size_t(pole);
        const float dist = distance_to(line, v, at);
        EXPECT_TRUE(at < 1e-3f || at > line.length - 2e-3f) << "a cap away from the stream's ends";
        EXPECT_LT(dist, 1.5f * kRadius);
    }
    EXPECT_EQ(count_open_edges(strided_positions(t.mesh.vertices, 6), t.mesh.indices), 0u);
}

TEST(OrientedScan, HorizontalHoseIsARoundTubeOfTheStreamsRadius) {
    const Centreline line = hose();
    expect_round_tube(line, extract(stream(line)), settings().u);
}

TEST(OrientedScan, ParabolicArcIsOneRoundTubeOverItsTop) {
    const Centreline line = arc();
    expect_round_tube(line, extract(stream(line)), settings().u);
}

// Each ring's radii against the seed's radial function over every sphere that cuts its plane, found by
// testing all of them: the job finds the cut planes by walking from each sphere's predecessor, and a
// sphere it missed (or one it gave the wrong ring) moves a radius. The ring's frame is read back from its
// vertices: the inner rings' pole sits at the centre, vertex 0 lies along the first axis, vertex u/4 along
// the second.
void expect_radii_from_every_cut(const Centreline& line) {
    const PointCloud c = stream(line);
    const Tube t = extract(c);
    const ScanSettings s = settings();
    ASSERT_EQ(s.u % 4, 0u);
    ASSERT_EQ(t.out.draw_count, 1u);
    const CylinderLayout layout{s.u, s.v};
    std::vector<float> cos_t(s.u), sin_t(s.u), r(s.u), tmp(s.u), cx, cz, rho;
    fill_angle_table(cos_t, sin_t);
    const auto vertex = [&](std::uint32_t index) {
        const float* v = t.out.vertices.data() + 6 * std::size_t(index);
        return Eigen::Vector3f(v[0], v[1], v[2]);
    };
    int compared = 0;
    for (std::uint32_t ring = t.out.draws[0].vmin + 1; ring < t.out.draws[0].vmax; ++ring) {
        const Eigen::Vector3f centre = vertex(layout.top_pole(ring));
        const Eigen::Vector3f n = (vertex(layout.side_vertex(ring, 0)) - centre).normalized();
        const Eigen::Vector3f b = (vertex(layout.side_vertex(ring, s.u / 4)) - centre).normalized();
        const Eigen::Vector3f tangent = n.cross(b);
        cx.clear(), cz.clear(), rho.clear();
        for (std::size_t i = 0; i < c.size(); ++i) {
            const Eigen::Vector3f d = Eigen::Vector3f(c.x[i], c.y[i], c.z[i]) - centre;
            const float h = d.dot(tangent);
            if (!(std::abs(h) < kRadius) || d.norm() > 10 * kRadius) continue;
            cx.push_back(d.dot(n)), cz.push_back(d.dot(b)),
                rho.push_back(std::sqrt(kRadius * kRadius - h * h));
        }
        if (cx.empty()) continue;
        circle_maxima({cx, cz, rho}, {cos_t, sin_t}, r);
        smooth_cyclic(r, s.section.smoothing_iterations, tmp);
        for (std::uint32_t k = 0; k < s.u; ++k)
            ASSERT_NEAR((vertex(layout.side_vertex(ring, k)) - centre).norm(), r[k], 2e-5f)
                << "ring " << ring << ", angle " << k << ", " << cx.size() << " spheres cut it";
        ++compared;
    }
    EXPECT_GT(compared, 40);
}

TEST(OrientedScan, RingRadiiComeFromEverySphereThatCutsTheirPlane) {
    expect_radii_from_every_cut(hose());
    expect_radii_from_every_cut(arc());
}

// What the paper's V-axis cylinders make of the same arc: rings near its top spread along the whole
// horizontal run, several stream radii wide (the reason for the path axis).
TEST(OrientedScan, VerticalCylindersSpreadTheArcsTop) {
    const Centreline line = arc();
    const PointCloud c = stream(line);
    ScanSettings s = settings();
    s.axis = CylinderAxis::kVertical;
    s.fit_v_range(c.y);
    ScanConverter scan(s, c.size());
    ScanOutput out;
    scan.prepare_output(out);
    scan.extract_serial(c.pos(), out);
    float widest = 0;
    const TriangleMesh mesh = assemble_scan_mesh(out, scan.layout(), kRadius);
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        float at = 0;
        widest = std::max(widest, distance_to(line, &mesh.vertices[6 * v], at));
    }
    EXPECT_GT(widest, 3 * kTube);
}

TEST(OrientedScan, SameBytesOnOneAndTwoThreadsAndSerial) {
    PointCloud c = stream(arc());
    const PointCloud h = stream(hose());
    for (std::size_t i = 0; i < h.size(); ++i) c.add(h.x[i], h.y[i] - 1.5f, h.z[i] + 1.0f);
    c.add(3.0f, 3.0f, 3.0f);  // an isolated particle
    const Tube serial = extract(c), one = extract(c, 1), two = extract(c, 2);
    EXPECT_EQ(serial.out.draw_count, 2u);
    EXPECT_EQ(serial.out.sphere_count, 1u);
    EXPECT_EQ(mesh_hash(serial.mesh), mesh_hash(one.mesh));
    EXPECT_EQ(mesh_hash(serial.mesh), mesh_hash(two.mesh));
}

}  // namespace
