// The public API (include/rivulet) against the command line's own path: the same surfaces, bytes for
// bytes, from a workspace that is reused, allocation-free once warm, independent of earlier calls and of
// the thread count; every error a rivulet::Error with the command line's message.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include "rivulet/rivulet.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/mesh_extraction.h"
#include "runtime/lib/recording.h"
#include "runtime/lib/scene_simulation.h"
#include "support/counting_new.h"
#include "support/test_support.h"
#include "systems/scan/scan_mesh.h"
#include "systems/scenes/scene_json.h"

using rivulet::MeshView;
using rivulet::Method;
using rivulet::SurfaceExtractor;
using rivulet::SurfaceSettings;

namespace {

// A ball of particles on a lattice `spacing` apart, `rings` lattice steps in radius, each moved by up to
// `jitter` spacings along each axis.
std::vector<float> ball(float spacing, int rings, float cx = 0.0f, std::uint32_t seed = 1,
                        float jitter = 0.1f) {
    std::vector<float> xyz;
    std::uint32_t h = seed;
    const auto shift = [&h, spacing, jitter] {
        h = h * 1664525u + 1013904223u;
        return 2.0f * jitter * spacing * (float(h >> 8) / float(1u << 24) - 0.5f);
    };
    for (int i = -rings; i <= rings; ++i)
        for (int j = -rings; j <= rings; ++j)
            for (int k = -rings; k <= rings; ++k)
                if (i * i + j * j + k * k <= rings * rings) {
                    xyz.push_back(cx + spacing * float(i) + shift());
                    xyz.push_back(spacing * float(j) + shift());
                    xyz.push_back(spacing * float(k) + shift());
                }
    return xyz;
}

rivulet::ParticleCloud cloud_of(const std::vector<float>& xyz) {
    rivulet::ParticleCloud c;
    for (std::size_t i = 0; i < xyz.size(); i += 3)
        c.x.push_back(xyz[i]), c.y.push_back(xyz[i + 1]), c.z.push_back(xyz[i + 2]);
    return c;
}

const char* method_name(Method m) {
    return m == Method::kSlices ? "slices" : m == Method::kScan ? "scan" : "volume";
}

std::uint64_t cli_hash(const std::vector<float>& xyz, Method m) {
    rivulet::MeshSettings req;
    req.method = method_name(m);
    return rivulet::extract_mesh(cloud_of(xyz), req).hash;
}

}  // namespace

class PublicApiMethod : public ::testing::TestWithParam<Method> {};

TEST_P(PublicApiMethod, SameBytesAsTheMeshCommand) {
    // Nearly a lattice: with more disorder the estimated radius (half the median neighbour distance)
    // leaves cavities inside the slices surface (docs/marching_slices.md, "Radius").
    const std::vector<float> xyz = ball(0.02f, 9, 0.0f, 1, 0.05f);
    SurfaceSettings s;
    s.method = GetParam();
    SurfaceExtractor extractor;
    const MeshView mesh = extractor.extract(xyz, s);
    EXPECT_GT(mesh.triangle_count(), 500u);
    EXPECT_EQ(rivulet::mesh_hash(mesh), cli_hash(xyz, GetParam()));
    // Around the ball (radius 0.18, particles of radius about 0.01): unit normals, and for the closed
    // surfaces normals pointing away from its centre (scan conversion's cylinder ends inside the ball
    // face up and down).
    std::size_t outward = 0;
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        const float* p = &mesh.vertices[6 * v];
        EXPECT_NEAR(std::hypot(p[3], p[4], p[5]), 1.0f, 1e-3f);
        EXPECT_LT(std::hypot(p[0], p[1], p[2]), 0.18f + 0.03f);
        outward += p[0] * p[3] + p[1] * p[4] + p[2] * p[5] > 0;
    }
    if (GetParam() != Method::kScan) {
        EXPECT_GT(double(outward), 0.99 * double(mesh.vertex_count()));
    }
}

TEST_P(PublicApiMethod, ArraysPerCoordinateGiveTheSameMesh) {
    const std::vector<float> xyz = ball(0.02f, 6);
    const rivulet::ParticleCloud c = cloud_of(xyz);
    SurfaceSettings s;
    s.method = GetParam();
    SurfaceExtractor a, b;
    EXPECT_EQ(rivulet::mesh_hash(a.extract(xyz, s)), rivulet::mesh_hash(b.extract(c.x, c.y, c.z, s)));
}

TEST_P(PublicApiMethod, AWarmWorkspaceRemembersNothing) {
    // Small then large, sparse then dense, other settings between: each result equals a fresh
    // extractor's.
    const std::vector<float> inputs[] = {ball(0.02f, 4), ball(0.015f, 10, 0.3f, 7), ball(0.03f, 6, -0.2f, 3),
                                         ball(0.02f, 4)};
    SurfaceExtractor warm;
    for (int round = 0; round < 2; ++round)
        for (const auto& xyz : inputs) {
            SurfaceSettings s;
            s.method = GetParam();
            s.radius = round == 0 ? 0.0f : 0.012f;
            SurfaceExtractor fresh;
            EXPECT_EQ(rivulet::mesh_hash(warm.extract(xyz, s)), rivulet::mesh_hash(fresh.extract(xyz, s)));
        }
}

TEST_P(PublicApiMethod, OneOrTwoThreadsSameBytes) {
    const std::vector<float> xyz = ball(0.015f, 12);
    SurfaceSettings s;
    s.method = GetParam();
    s.threads = 1;
    SurfaceExtractor one, two;
    const std::uint64_t h1 = rivulet::mesh_hash(one.extract(xyz, s));
    s.threads = 2;
    EXPECT_EQ(h1, rivulet::mesh_hash(two.extract(xyz, s)));
}

INSTANTIATE_TEST_SUITE_P(Methods, PublicApiMethod,
                         ::testing::Values(Method::kSlices, Method::kScan, Method::kVolume),
                         [](const auto& p) { return std::string(method_name(p.param)); });

// With the same settings (the radius included: an estimate that comes out different is a new radius,
// which rebuilds the method) and no more particles than before.
class PublicApiSteadyState : public ::testing::TestWithParam<float> {};

TEST_P(PublicApiSteadyState, SlicesAllocateNothingOnceWarm) {
    const std::vector<float> a = ball(0.02f, 8), b = ball(0.02f, 8, 0.01f, 5), c = ball(0.02f, 6);
    SurfaceSettings s;
    s.threads = 2;
    s.radius = 0.011f;
    s.anisotropy = GetParam();
    SurfaceExtractor extractor;
    for (int i = 0; i < 10; ++i) extractor.extract(i % 3 == 0 ? c : i % 2 ? b : a, s);
    long before = rivulet::test::allocation_count();
    std::uint64_t triangles = 0;
    for (int i = 0; i < 10; ++i)
        triangles += extractor.extract(i % 3 == 0 ? c : i % 2 ? b : a, s).triangle_count();
    long during = rivulet::test::allocation_count() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 10 warm calls";
    EXPECT_GT(triangles, 10000u);
    // An estimated radius: the same input again is the same radius.
    s.radius = 0;
    for (int i = 0; i < 3; ++i) extractor.extract(a, s);
    before = rivulet::test::allocation_count();
    for (int i = 0; i < 3; ++i) extractor.extract(a, s);
    during = rivulet::test::allocation_count() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 3 warm calls, radius estimated";
}

INSTANTIATE_TEST_SUITE_P(Kernels, PublicApiSteadyState, ::testing::Values(0.0f, 3.0f),
                         [](const auto& p) { return p.param > 0 ? "Anisotropic" : "Spheres"; });

TEST(PublicApi, ErrorsAreRivuletErrorsWithTheCommandLinesWords) {
    SurfaceExtractor e;
    const auto message = [](auto&& f) -> std::string {
        try {
            f();
        } catch (const rivulet::Error& err) {
            return err.what();
        }
        return "no error";
    };
    SurfaceSettings s;
    EXPECT_EQ(message([&] { e.extract(std::span<const float>{}, s); }), "no particles to mesh");
    std::vector<float> xyz = ball(0.02f, 3);
    EXPECT_NE(message([&] { e.extract(std::span<const float>(xyz).first(4), s); }).find("3 a particle"),
              std::string::npos);
    xyz[7] = std::nanf("");
    EXPECT_NE(message([&] { e.extract(xyz, s); }).find("particle 2 "), std::string::npos);
    xyz[7] = 0;
    s.radius = -1;
    EXPECT_NE(message([&] { e.extract(xyz, s); }).find("radius"), std::string::npos);
    s.radius = 0, s.threads = 5000;
    EXPECT_NE(message([&] { e.extract(xyz, s); }).find("threads"), std::string::npos);
    s.threads = 0, s.anisotropy = 9;
    EXPECT_NE(message([&] { e.extract(xyz, s); }).find("anisotrop"), std::string::npos);
    // The extractor still works after errors.
    s.anisotropy = 0;
    EXPECT_GT(e.extract(xyz, s).triangle_count(), 0u);

    EXPECT_NE(message([] { rivulet::load_particles("/nonexistent/p.ply"); }).find("/nonexistent/p.ply"),
              std::string::npos);
    EXPECT_NE(message([] { rivulet::Simulation("no_such_scene"); }).find("no_such_scene"), std::string::npos);
    EXPECT_NE(message([] { rivulet::Simulation("dambreak", 2'000'000); }).find("warmup"), std::string::npos);
}

TEST(PublicApi, ParticleFilesRoundTrip) {
    const std::vector<float> xyz = ball(0.02f, 3);
    const std::string path = rivulet::test::temp_path("api_particles.ply");
    rivulet::save_particles(path, xyz);
    EXPECT_EQ(rivulet::load_particles(path).xyz, xyz);
    std::remove(path.c_str());
}

TEST(PublicApi, SimulationIsTheSceneSimulationAtAnyThreadCount) {
    // The SPH dam break at a tenth of the built-in one's particles, from a scene file.
    const std::string scene = std::string(RIVULET_SOURCE_DIR) + "/tests/golden/dambreak_small.json";
    rivulet::Simulation one(scene, 0, 1), two(scene, 0, 2);
    rivulet::SceneSimulation reference(rivulet::resolve_scene(scene));
    rivulet::FrameGraph graph;
    reference.add_jobs(graph);
    for (int f = 0; f < 3; ++f) {
        one.step(), two.step(), graph.run();
        const rivulet::PositionsView a = one.positions(), b = two.positions();
        const rivulet::ConstPositions r = reference.particles().positions();
        ASSERT_GT(a.size(), 2000u);
        ASSERT_EQ(a.size(), r.size());
        ASSERT_EQ(b.size(), r.size());
        for (std::size_t i = 0; i < a.size(); ++i) {
            ASSERT_TRUE(a.x[i] == r.x[i] && a.y[i] == r.y[i] && a.z[i] == r.z[i])
                << "1 thread, particle " << i;
            ASSERT_TRUE(b.x[i] == r.x[i] && b.y[i] == r.y[i] && b.z[i] == r.z[i])
                << "2 threads, particle " << i;
        }
    }
    EXPECT_EQ(one.frame(), 3u);
    EXPECT_EQ(one.name(), "dambreak_small");
    EXPECT_GT(one.particle_radius(), 0.0f);
    const auto scenes = rivulet::Simulation::builtin_scenes();
    EXPECT_NE(std::find(scenes.begin(), scenes.end(), "dambreak"), scenes.end());
}

TEST(PublicApi, ReplayReportsARecordedRunAndTheFirstFrameThatDiffers) {
    const std::string golden = std::string(RIVULET_SOURCE_DIR) + "/tests/golden/faucet_scan.rivrec";
    const rivulet::ReplayReport same = rivulet::replay(golden, 4, 2);
    EXPECT_TRUE(same.identical);
    EXPECT_EQ(same.scene, "faucet");
    EXPECT_EQ(same.method, "scan");
    EXPECT_EQ(same.recorded, 100u);
    EXPECT_EQ(same.frames, 4u);

    // The same recording with its third frame's surface hash changed in one bit.
    rivulet::Recording rec = rivulet::read_recording(golden);
    rec.frames[2].surface ^= 1;
    const std::string tampered = rivulet::test::temp_path("tampered.rivrec");
    rivulet::write_recording(tampered, rec);
    const rivulet::ReplayReport diff = rivulet::replay(tampered, 4, 1);
    EXPECT_FALSE(diff.identical);
    EXPECT_EQ(diff.frames, 4u);
    EXPECT_EQ(diff.frame, 2u);
    EXPECT_EQ(diff.simulation_frame, 30u + 2u);  // after the scene's 30 warm-up frames
    EXPECT_EQ(diff.buffer, "surface");
    EXPECT_EQ(diff.recorded_hash, rec.frames[2].surface);
    EXPECT_EQ(diff.replayed_hash, rec.frames[2].surface ^ 1);
    std::remove(tampered.c_str());

    EXPECT_THROW(rivulet::replay(tampered), rivulet::Error);  // gone
    EXPECT_THROW(rivulet::replay(golden, -1), rivulet::Error);
    EXPECT_THROW(rivulet::replay(golden, 1, -2), rivulet::Error);
}

namespace {

// Frame f of a host's simulation: a ball that moves along x and changes its jitter.
std::vector<float> host_frame(std::uint64_t f) {
    return ball(0.02f, 5, 0.004f * float(f), std::uint32_t(f + 1));
}

}  // namespace

TEST(PublicApi, SurfacePipelineRendersEveryFrameInOrderWithTheExtractorsMesh) {
    SurfaceSettings settings;
    settings.radius = 0.012f;
    settings.threads = 2;
    constexpr std::uint64_t kFrames = 6;
    std::vector<std::uint64_t> expected;
    SurfaceExtractor reference;
    for (std::uint64_t f = 0; f < kFrames; ++f)
        expected.push_back(rivulet::mesh_hash(reference.extract(host_frame(f), settings)));

    for (const bool overlap : {true, false}) {
        rivulet::SurfacePipeline pipeline(settings);
        pipeline.set_overlap(overlap);
        std::vector<std::uint64_t> rendered, hashes;
        std::atomic<std::uint64_t> stepped{0};
        std::atomic<bool> overlapped{false};
        pipeline.run(
            kFrames,
            [&](std::uint64_t f, std::vector<float>& xyz) {
                EXPECT_EQ(f, stepped.load());
                xyz = host_frame(f);
                stepped = f + 1;
            },
            [&](std::uint64_t f, std::span<const float> xyz, const MeshView& mesh) {
                rendered.push_back(f);
                hashes.push_back(rivulet::mesh_hash(mesh));
                EXPECT_TRUE(std::ranges::equal(xyz, host_frame(f))) << "frame " << f;
                // With overlap, frame f + 1 is stepped while frame f renders: wait for it (bounded, so a
                // pipeline that does not overlap fails instead of hanging).
                if (overlap && f + 1 < kFrames && tbb::this_task_arena::max_concurrency() > 1) {
                    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
                    while (stepped.load() < f + 2 && std::chrono::steady_clock::now() < until)
                        std::this_thread::sleep_for(std::chrono::microseconds(100));
                    if (stepped.load() >= f + 2) overlapped = true;
                }
                if (!overlap) {
                    EXPECT_EQ(stepped.load(), f + 1) << "frame " << f;
                }
            });
        EXPECT_EQ(rendered, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5}));
        EXPECT_EQ(hashes, expected) << (overlap ? "overlapped" : "serial");
        if (overlap && tbb::this_task_arena::max_concurrency() > 1) {
            EXPECT_TRUE(overlapped.load());
        }
    }
}

TEST(PublicApi, SurfacePipelineStopsOnTheFirstExceptionAndRunsAgain) {
    SurfaceSettings settings;
    settings.radius = 0.012f;
    rivulet::SurfacePipeline pipeline(settings);
    std::vector<std::uint64_t> rendered;
    auto step = [](std::uint64_t f, std::vector<float>& xyz) {
        if (f == 3) throw std::runtime_error("host simulation failed at frame 3");
        xyz = host_frame(f);
    };
    auto render = [&](std::uint64_t f, std::span<const float>, const MeshView&) { rendered.push_back(f); };
    try {
        pipeline.run(10, step, render);
        ADD_FAILURE() << "the step's exception did not leave run()";
    } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), "host simulation failed at frame 3");
    }
    EXPECT_EQ(rendered, (std::vector<std::uint64_t>{0, 1, 2}));

    // A render that throws, then a step that gives no particles (the extractor's error), then a clean run.
    rendered.clear();
    EXPECT_THROW(pipeline.run(
                     10, [](std::uint64_t f, std::vector<float>& xyz) { xyz = host_frame(f); },
                     [](std::uint64_t f, std::span<const float>, const MeshView&) {
                         if (f == 1) throw std::logic_error("render failed");
                     }),
                 std::logic_error);
    EXPECT_THROW(pipeline.run(
                     4, [](std::uint64_t, std::vector<float>& xyz) { xyz.clear(); }, render),
                 rivulet::Error);
    EXPECT_TRUE(rendered.empty());
    pipeline.run(
        2, [](std::uint64_t f, std::vector<float>& xyz) { xyz = host_frame(f); }, render);
    EXPECT_EQ(rendered, (std::vector<std::uint64_t>{0, 1}));
    EXPECT_THROW(pipeline.run(1, nullptr, render), rivulet::Error);
}
