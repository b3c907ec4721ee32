// The stream producer: determinism at any integrate() split, counter-based emission, ballistic accuracy,
// contacts, the height-field pool and the built-in scenes' steady state.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include "jobs/counter_rng.h"
#include "systems/render/camera.h"
#include "systems/scenes/scene.h"
#include "systems/sim/height_field_pool.h"
#include "systems/sim/stream_sim.h"

#include "support/counting_new.h"

namespace rivulet {
namespace {

// The built-in scenes whose particles come from stream emitters (the others are SPH).
std::vector<std::string_view> stream_scene_names() {
    std::vector<std::string_view> names;
    for (std::string_view n : builtin_scene_names())
        if (make_builtin_scene(n).simulation == SimulationKind::kStreams) names.push_back(n);
    return names;
}

std::uint64_t fnv1a(std::uint64_t h, const void* data, std::size_t bytes) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ b[i]) * 0x100000001b3ull;
    return h;
}

template <class T>
std::uint64_t fnv1a(std::uint64_t h, std::span<const T> s) {
    return fnv1a(h, s.data(), s.size_bytes());
}

std::uint64_t hash_state(const ParticleSet& ps, const HeightFieldView& pool) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    h = fnv1a(h, ps.x()), h = fnv1a(h, ps.y()), h = fnv1a(h, ps.z());
    h = fnv1a(h, ps.vx()), h = fnv1a(h, ps.vy()), h = fnv1a(h, ps.vz());
    h = fnv1a(h, ps.id());
    return fnv1a(h, pool.heights);
}

// Uneven chunks covering [0, n), the last chunk first; no storage, so the allocation test can use it.
void integrate_split(StreamSimulation& sim, ParticleSet& ps, std::uint64_t frame) {
    std::size_t end = ps.size();
    for (std::size_t k = 0; end > 0; ++k) {
        const std::size_t len = std::min<std::size_t>(end, 1 + (frame * 37 + k * 101) % 997);
        sim.integrate(ps, end - len, end);
        end -= len;
    }
}

// Nothing in reach: no emitters, no colliders, no pool, ground far below.
SceneDesc open_scene() {
    SceneDesc s;
    s.name = "open";
    s.ground_y = -1000.0f;
    s.lifetime = 100.0f;
    s.max_particles = 1024;
    return s;
}

bool all_finite(const ParticleSet& ps) {
    for (std::span<const float> a : {ps.x(), ps.y(), ps.z(), ps.vx(), ps.vy(), ps.vz()}) {
        for (float v : a) {
            if (!std::isfinite(v)) return false;
        }
    }
    return true;
}

float sample_at(const HeightFieldView& v, int ix, int iz) {
    return v.heights[static_cast<std::size_t>(iz) * v.nx + ix];
}

TEST(StreamSim, AnyIntegrateSplitGivesBitIdenticalFrames) {
    for (std::string_view name : stream_scene_names()) {
        const SceneDesc scene = make_builtin_scene(name);
        StreamSimulation whole(scene), split(scene);
        ParticleSet a(scene.max_particles), b(scene.max_particles);
        for (std::uint64_t frame = 0; frame < 120; ++frame) {
            whole.begin_frame(a, frame);
            whole.integrate(a, 0, a.size());
            whole.end_frame(a);
            split.begin_frame(b, frame);
            integrate_split(split, b, frame);
            split.end_frame(b);
            ASSERT_EQ(a.size(), b.size()) << name << " frame " << frame;
            ASSERT_EQ(hash_state(a, whole.pool_view()), hash_state(b, split.pool_view()))
                << name << " frame " << frame;
        }
        EXPECT_GT(a.size(), 1000u) << name;
    }
}

TEST(StreamSim, EmittedStateDependsOnlyOnSeedFrameAndId) {
    SceneDesc small = make_builtin_scene("fountain");
    SceneDesc large = small;
    large.max_particles = small.max_particles + 7777;
    // An emitter appended at the end takes later ids, so the others' particles keep theirs.
    large.emitters.push_back({{3, 1, 3}, {0, 1, 0}, 2.0f, 0.1f, 0.05f, 3000.0f});
    StreamSimulation sa(small), sb(large);
    ParticleSet a(small.max_particles), b(large.max_particles);
    sa.begin_frame(a, 5);
    sb.begin_frame(b, 5);
    ASSERT_GT(a.size(), 100u);
    ASSERT_GT(b.size(), a.size());
    const std::size_t n = a.size();
    EXPECT_EQ(0, std::memcmp(a.x().data(), b.x().data(), n * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.y().data(), b.y().data(), n * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.z().data(), b.z().data(), n * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.vx().data(), b.vx().data(), n * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.vy().data(), b.vy().data(), n * sizeof(float)));
    EXPECT_EQ(0, std::memcmp(a.vz().data(), b.vz().data(), n * sizeof(float)));
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(a.id()[i], i);

    // A different frame number draws different jitter for the same ids.
    StreamSimulation sc(small);
    ParticleSet c(small.max_particles);
    sc.begin_frame(c, 6);
    ASSERT_EQ(c.size(), n);
    EXPECT_NE(0, std::memcmp(a.x().data(), c.x().data(), n * sizeof(float)));
}

TEST(StreamSim, EmissionRateCarriesFractions) {
    SceneDesc s = open_scene();
    s.emitters.push_back({{0, 0, 0}, {0, 1, 0}, 1.0f, 0.0f, 0.0f, 90.0f});  // 1.5 per frame at 60 Hz
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    for (std::uint64_t f = 0; f < 10; ++f) sim.step_serial(ps, f);
    EXPECT_EQ(sim.next_id(), 15u);
    EXPECT_EQ(ps.size(), 15u);
}

TEST(StreamSim, EmissionStopsWhenFullWithoutGrowing) {
    SceneDesc s = open_scene();
    s.max_particles = 100;
    s.emitters.push_back({{0, 0, 0}, {0, 1, 0}, 1.0f, 0.0f, 0.0f, 6000.0f});
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    for (std::uint64_t f = 0; f < 5; ++f) sim.step_serial(ps, f);
    EXPECT_EQ(ps.size(), 100u);
    EXPECT_EQ(ps.capacity(), 100u);
    EXPECT_EQ(sim.next_id(), 100u);
}

TEST(StreamSim, FrameLoopDoesNotAllocate) {
    const SceneDesc scene = make_builtin_scene("faucet");  // emitters, sphere, boxes and pool
    StreamSimulation sim(scene);
    ParticleSet ps(scene.max_particles);
    const std::size_t before = rivulet::test::allocation_count();
    for (std::uint64_t f = 0; f < 200; ++f) {
        sim.begin_frame(ps, f);
        integrate_split(sim, ps, f);
        sim.end_frame(ps);
    }
    EXPECT_EQ(rivulet::test::allocation_count(), before);
    EXPECT_GT(ps.size(), 1000u);
}

// Semi-implicit Euler with step h = dt / substeps gives, after n steps (t = n h), exactly
//   p = p0 + v0 t + g t^2 / 2 + g h t / 2,   v = v0 + g t,
// so the error against the closed form is |g| h t / 2 (4.1 cm after 1 s at h = 1/120 s), and the
// position must match the scheme's own formula up to float rounding (2e-4 m over 120 steps).
TEST(StreamSim, BallisticFlightMatchesClosedForm) {
    SceneDesc s = open_scene();
    s.substeps = 2;
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    const Vec3f p0{0.25f, 5.0f, -1.0f}, v0{1.0f, 3.0f, -0.5f};
    ps.push(p0.x, p0.y, p0.z, v0.x, v0.y, v0.z, 0);
    const int frames = 60;
    for (int f = 0; f < frames; ++f) sim.step_serial(ps, static_cast<std::uint64_t>(f));
    ASSERT_EQ(ps.size(), 1u);

    const double t = frames * double(s.dt), h = double(s.dt) / s.substeps;
    const double g[3] = {s.gravity.x, s.gravity.y, s.gravity.z};
    const double p_init[3] = {p0.x, p0.y, p0.z}, v_init[3] = {v0.x, v0.y, v0.z};
    const float got_p[3] = {ps.x()[0], ps.y()[0], ps.z()[0]};
    const float got_v[3] = {ps.vx()[0], ps.vy()[0], ps.vz()[0]};
    for (int a = 0; a < 3; ++a) {
        const double exact = p_init[a] + v_init[a] * t + 0.5 * g[a] * t * t;
        const double euler = exact + 0.5 * g[a] * h * t;
        EXPECT_NEAR(got_p[a], euler, 2e-4) << "axis " << a;
        EXPECT_LE(std::abs(got_p[a] - exact), 0.5 * std::abs(g[a]) * h * t + 2e-4) << "axis " << a;
        EXPECT_NEAR(got_v[a], v_init[a] + g[a] * t, 1e-4) << "axis " << a;
    }
}

TEST(StreamSim, GroundHoldsParticlesAndRecyclesResting) {
    SceneDesc s = open_scene();
    s.ground_y = 0.0f;
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    for (std::uint32_t i = 0; i < 300; ++i) {
        const auto u = [&](std::uint64_t k) { return counter_uniform(99, 0, i, k); };
        ps.push(4 * u(0) - 2, 0.05f + 2 * u(1), 4 * u(2) - 2, 2 * u(3) - 1, -12 * u(4), 2 * u(5) - 1, i);
    }
    for (std::uint64_t f = 0; f < 400 && !ps.empty(); ++f) {
        sim.step_serial(ps, f);
        for (float y : ps.y()) ASSERT_GE(y, s.ground_y + s.particle_radius - 1e-5f) << "frame " << f;
    }
    EXPECT_TRUE(ps.empty()) << ps.size() << " particles never came to rest";
}

TEST(StreamSim, ParticlesNeverEndInsideSphereOrBox) {
    SceneDesc s = open_scene();
    s.ground_y = -5.0f;
    s.spheres.push_back({{0.0f, 1.0f, 0.0f}, 0.3f});
    s.boxes.push_back({{1.7f, 0.5f, -0.3f}, {2.3f, 1.0f, 0.3f}});
    s.emitters.push_back({{0.08f, 2.0f, 0.0f}, {0, -1, 0}, 1.0f, 0.05f, 0.03f, 2000.0f});
    s.emitters.push_back({{1.9f, 2.0f, 0.1f}, {0, -1, 0}, 1.0f, 0.05f, 0.03f, 2000.0f});
    s.max_particles = 8192;
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    const float r = s.particle_radius, tol = 1e-4f;
    float max_sphere_deflection = 0;
    for (std::uint64_t f = 0; f < 90; ++f) {
        sim.step_serial(ps, f);
        for (std::size_t i = 0; i < ps.size(); ++i) {
            const Vec3f p{ps.x()[i], ps.y()[i], ps.z()[i]};
            ASSERT_GE(length(p - s.spheres[0].center), s.spheres[0].radius + r - tol) << "frame " << f;
            const BoxCollider& b = s.boxes[0];
            const bool in_box = p.x > b.min.x - r + tol && p.x < b.max.x + r - tol &&
                                p.y > b.min.y - r + tol && p.y < b.max.y + r - tol &&
                                p.z > b.min.z - r + tol && p.z < b.max.z + r - tol;
            ASSERT_FALSE(in_box) << "frame " << f;
            if (p.x < 1.0f) max_sphere_deflection = std::max(max_sphere_deflection, std::abs(p.x));
        }
    }
    // The streams really met the obstacles: the sphere throws its stream sideways.
    EXPECT_GT(max_sphere_deflection, 0.35f);
}

PoolDesc test_pool() {
    PoolDesc p;
    p.enabled = true;
    p.x0 = -1, p.z0 = -1, p.size_x = 2, p.size_z = 2;
    p.nx = 129, p.nz = 129;
    p.level = 0.25f;
    p.wave_speed = 1.0f;
    p.damping = 0.5f;
    p.impulse_scale = 0.002f;
    p.max_dip = 0.05f;
    return p;
}

TEST(HeightFieldPool, CalmPoolStaysExactlyCalm) {
    HeightFieldPool pool(test_pool(), 1.0f / 60.0f);
    for (int f = 0; f < 200; ++f) pool.step();
    for (float h : pool.view().heights) ASSERT_EQ(h, 0.25f);
    EXPECT_EQ(pool.deviation_energy(), 0.0);
}

TEST(HeightFieldPool, HitDipsLocallyAndTheWaveTravelsAtWaveSpeed) {
    const PoolDesc desc = test_pool();
    const float dt = 1.0f / 60.0f;
    HeightFieldPool pool(desc, dt);
    EXPECT_GE(pool.substeps(), 2);  // c dt / dx ~ 1.07 here: one explicit step per frame would blow up
    pool.apply_impulse(0.0f, 0.0f, 10.0f);  // (0, 0) is sample (64, 64)
    const HeightFieldView v = pool.view();
    EXPECT_FLOAT_EQ(sample_at(v, 64, 64), desc.level - 10.0f * desc.impulse_scale);
    EXPECT_EQ(sample_at(v, 70, 64), desc.level);

    // A sample 0.5 m away: still (to numerical precursors) well before d / c, moving around d / c.
    const float d = 0.5f;
    const int probe = 64 + 32;  // dx = 2 / 128
    const int arrival = static_cast<int>(std::lround(d / desc.wave_speed / dt));
    std::vector<float> dev;
    for (int f = 0; f < 2 * arrival; ++f) {
        pool.step();
        dev.push_back(std::abs(sample_at(pool.view(), probe, 64) - desc.level));
    }
    const float peak = *std::max_element(dev.begin(), dev.end());
    ASSERT_GT(peak, 1e-5f);
    const float early = *std::max_element(dev.begin(), dev.begin() + arrival / 2);
    EXPECT_LT(early, 0.01f * peak);
    const auto first = std::find_if(dev.begin(), dev.end(), [&](float x) { return x > 0.2f * peak; });
    const int first_frame = static_cast<int>(first - dev.begin()) + 1;
    EXPECT_GE(first_frame, static_cast<int>(0.7 * arrival));
    EXPECT_LE(first_frame, static_cast<int>(1.3 * arrival));
}

TEST(HeightFieldPool, DampingDrainsEnergy) {
    HeightFieldPool pool(test_pool(), 1.0f / 60.0f);
    for (int k = 0; k < 5; ++k) pool.apply_impulse(-0.3f + 0.15f * static_cast<float>(k), 0.1f, 8.0f);
    std::vector<double> window_mean;
    double sum = 0;
    for (int f = 1; f <= 360; ++f) {
        pool.step();
        sum += pool.deviation_energy();
        if (f % 60 == 0) window_mean.push_back(sum / 60), sum = 0;
    }
    for (std::size_t w = 1; w < window_mean.size(); ++w) EXPECT_LT(window_mean[w], window_mean[w - 1]) << w;
    EXPECT_LT(window_mean.back(), 0.1 * window_mean.front());
}

TEST(HeightFieldPool, ImpulsesAreClampedAndOutsideHitsIgnored) {
    PoolDesc desc = test_pool();
    HeightFieldPool pool(desc, 1.0f / 60.0f);
    pool.apply_impulse(5.0f, 0.0f, 10.0f);
    EXPECT_EQ(pool.deviation_energy(), 0.0);
    for (int k = 0; k < 50; ++k) pool.apply_impulse(0.0f, 0.0f, 1000.0f);
    for (float h : pool.view().heights) ASSERT_GE(h, desc.level - desc.max_dip);
    EXPECT_FLOAT_EQ(sample_at(pool.view(), 64, 64), desc.level - desc.max_dip);
}

TEST(StreamSim, StreamIntoPoolIsAbsorbedAndDentsTheSurface) {
    SceneDesc s = open_scene();
    s.ground_y = 0.0f;
    s.pool = test_pool();
    s.emitters.push_back({{0.0f, 1.5f, 0.0f}, {0, -1, 0}, 0.5f, 0.02f, 0.02f, 1200.0f});
    StreamSimulation sim(s);
    ParticleSet ps(s.max_particles);
    float lowest = s.pool.level;
    for (std::uint64_t f = 0; f < 120; ++f) {
        sim.step_serial(ps, f);
        for (float h : sim.pool_view().heights) lowest = std::min(lowest, h);
        // Absorbed at the surface: nothing lives below it (plus one frame of motion).
        for (float y : ps.y()) ASSERT_GT(y, s.pool.level - s.pool.max_dip - 0.1f);
    }
    EXPECT_LT(lowest, s.pool.level - 0.005f);
    EXPECT_GT(sim.next_id(), ps.size() + 500);  // most particles were absorbed
    EXPECT_LT(ps.size(), 1000u);
}

struct SteadyRange {
    std::string_view name;
    std::size_t lo, hi;
};

TEST(BuiltinScenes, ReachTheirSteadyStateWithinWarmup) {
    const SteadyRange ranges[] = {{"fountain", 7000, 9000}, {"faucet", 3000, 8000}, {"hose", 4000, 8000}};
    ASSERT_EQ(stream_scene_names().size(), std::size(ranges));
    for (const SteadyRange& r : ranges) {
        const SceneDesc s = make_builtin_scene(r.name);
        EXPECT_EQ(s.name, r.name);
        EXPECT_GE(s.warmup_frames, 90);
        EXPECT_LE(s.warmup_frames, 150);
        StreamSimulation sim(s);
        ParticleSet ps(s.max_particles);
        std::uint64_t frame = 0;
        for (; frame < static_cast<std::uint64_t>(s.warmup_frames); ++frame) sim.step_serial(ps, frame);
        for (int k = 0; k < 120; ++k, ++frame) {
            ASSERT_GE(ps.size(), r.lo) << r.name << " frame " << frame;
            ASSERT_LE(ps.size(), r.hi) << r.name << " frame " << frame;
            ASSERT_GE(s.max_particles, ps.size() * 3 / 2) << r.name;
            ASSERT_TRUE(all_finite(ps)) << r.name;
            for (float y : ps.y()) ASSERT_TRUE(y >= s.v_min && y <= s.v_max) << r.name << " y " << y;
            sim.step_serial(ps, frame);
        }
    }
}

TEST(BuiltinScenes, CameraFramesTheStreamsAndThePool) {
    constexpr int kWidth = 1280, kHeight = 720;
    for (std::string_view name : stream_scene_names()) {
        const SceneDesc s = make_builtin_scene(name);
        StreamSimulation sim(s);
        ParticleSet ps(s.max_particles);
        for (int f = 0; f < s.warmup_frames; ++f) sim.step_serial(ps, static_cast<std::uint64_t>(f));
        float px = 0, py = 0, left = kWidth, right = 0;
        for (std::size_t i = 0; i < ps.size(); ++i) {
            ASSERT_TRUE(
                project_to_pixel(s.camera, kWidth, kHeight, {ps.x()[i], ps.y()[i], ps.z()[i]}, px, py))
                << name;
            left = std::min(left, px), right = std::max(right, px);
        }
        const PoolDesc& p = s.pool;
        for (float a : {0.0f, 1.0f}) {
            for (float b : {0.0f, 1.0f}) {
                const Vec3f corner{p.x0 + a * p.size_x, p.level, p.z0 + b * p.size_z};
                EXPECT_TRUE(project_to_pixel(s.camera, kWidth, kHeight, corner, px, py)) << name;
            }
        }
        EXPECT_GT(right - left, 0.1f * kWidth) << name << ": the action is a speck";
    }
}

TEST(BuiltinScenes, SphScenesFrameTheirWholeTank) {
    constexpr int kWidth = 1280, kHeight = 720;
    for (std::string_view name : {"dambreak", "drop", "slosh"}) {
        const SceneDesc s = make_builtin_scene(name);
        ASSERT_EQ(s.simulation, SimulationKind::kSph) << name;
        const BoxCollider& b = s.sph.bounds;
        float px = 0, py = 0, left = kWidth, right = 0;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3f c{corner & 1 ? b.max.x : b.min.x, corner & 2 ? b.max.y : b.min.y,
                          corner & 4 ? b.max.z : b.min.z};
            ASSERT_TRUE(project_to_pixel(s.camera, kWidth, kHeight, c, px, py))
                << name << " corner " << corner;
            left = std::min(left, px), right = std::max(right, px);
        }
        EXPECT_GT(right - left, 0.3f * kWidth) << name << ": the tank is small in the picture";
        EXPECT_EQ(s.particle_radius, 0.5f * s.sph.spacing) << name;
        EXPECT_GE(s.max_particles, sph_seed_count(s.sph)) << name;
    }
}

TEST(BuiltinScenes, FountainIsDefaultAndUnknownNamesThrow) {
    ASSERT_FALSE(builtin_scene_names().empty());
    EXPECT_EQ(builtin_scene_names().front(), "fountain");
    EXPECT_EQ(make_builtin_scene("fountain").emitters.size(), 12u);
    try {
        make_builtin_scene("nope");
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        for (std::string_view n : builtin_scene_names()) EXPECT_NE(what.find(n), std::string::npos) << what;
    }
}

TEST(StreamSim, RejectsAbsurdScenes) {
    const std::vector<void (*)(SceneDesc&)> breakers = {
        [](SceneDesc& s) { s.dt = 0; },
        [](SceneDesc& s) { s.dt = -0.01f; },
        [](SceneDesc& s) { s.dt = 2; },
        [](SceneDesc& s) { s.dt = std::nanf(""); },
        [](SceneDesc& s) { s.substeps = 0; },
        [](SceneDesc& s) { s.substeps = 65; },
        [](SceneDesc& s) { s.max_particles = 0; },
        [](SceneDesc& s) { s.max_particles = 50'000'001; },
        [](SceneDesc& s) { s.particle_radius = 0; },
        [](SceneDesc& s) { s.particle_radius = -0.01f; },
        [](SceneDesc& s) { s.gravity.y = INFINITY; },
        [](SceneDesc& s) { s.lifetime = std::nanf(""); },
        [](SceneDesc& s) { s.pool.nx = 1; },
        [](SceneDesc& s) { s.pool.nz = 4097; },
        [](SceneDesc& s) { s.pool.wave_speed = std::nanf(""); },
        [](SceneDesc& s) { s.emitters[0].rate = INFINITY; },
        [](SceneDesc& s) { s.emitters[0].position.x = std::nanf(""); },
        [](SceneDesc& s) {
            s.spheres.push_back({{0, 0, 0}, std::nanf("")});
        },
        [](SceneDesc& s) { s.camera.fov_y_deg = std::nanf(""); },
    };
    EXPECT_NO_THROW(StreamSimulation{make_builtin_scene("fountain")});
    for (std::size_t k = 0; k < breakers.size(); ++k) {
        SceneDesc s = make_builtin_scene("fountain");
        breakers[k](s);
        EXPECT_THROW(StreamSimulation{s}, std::invalid_argument) << "case " << k;
    }
}

}  // namespace
}  // namespace rivulet
