// Diffuse objects (Juckel & Beckhaus, "Rendering diffuse objects using particle systems inside voxelized
// surface geometry"): each force against its closed-form path, emission within the maximum density,
// fading and re-entry, collisions that leave no particle inside a solid, the back-to-front order of the
// staged sprites, and the same bytes at 1 and 2 threads, replayed from a recording.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

#include "jobs/depth_radix_sort.h"
#include "jobs/diffuse_update.h"
#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/recording.h"
#include "runtime/lib/scene_simulation.h"
#include "support/test_support.h"
#include "systems/diffuse/collider_mesh.h"
#include "systems/diffuse/diffuse_simulation.h"
#include "systems/scenes/scene_json.h"

namespace rivulet {
namespace {

constexpr float kDt = 1.0f / 60.0f;

void expect_near(Vec3f a, Vec3f b, float tol, const char* what) {
    EXPECT_NEAR(a.x, b.x, tol) << what;
    EXPECT_NEAR(a.y, b.y, tol) << what;
    EXPECT_NEAR(a.z, b.z, tol) << what;
}

// Steps one particle `n` times under `force` about `centre` with no drag.
void run(const VoxelForce& force, Vec3f centre, Vec3f accel, int n, Vec3f& p, Vec3f& v) {
    const VoxelStep step = make_voxel_step(force, 0, kDt);
    for (int i = 0; i < n; ++i) apply_voxel_step(step, centre, accel, p, v);
}

TEST(DiffuseForces, LinearFollowsTheParabola) {
    const VoxelForce f{1, {0.5f, -2.0f, 0.25f}, 0, 0};
    const Vec3f p0{0.1f, 1, 0}, v0{1, 2, 0};
    Vec3f p = p0, v = v0;
    const Vec3f wind{0.2f, 0, 0};
    run(f, {}, wind, 120, p, v);
    const float t = 120 * kDt;
    const Vec3f a = f.vector + wind;
    expect_near(p, p0 + v0 * t + a * (0.5f * t * t), 2e-4f, "position");
    expect_near(v, v0 + a * t, 2e-4f, "velocity");
}

TEST(DiffuseForces, OrbitFollowsTheEllipseAndKeepsItsEnergy) {
    const float w = 2.0f;
    const VoxelForce f{3, {}, w, 0};
    const Vec3f c{0.3f, 1, -0.2f}, d0{0.2f, 0, 0}, v0{0, 0.3f, 0.1f};
    Vec3f p = c + d0, v = v0;
    run(f, c, {}, 300, p, v);
    const float t = 300 * kDt;
    expect_near(p, c + d0 * std::cos(w * t) + v0 * (std::sin(w * t) / w), 1e-4f, "orbit");
    const Vec3f d = p - c;
    EXPECT_NEAR(dot(v, v) + w * w * dot(d, d), dot(v0, v0) + w * w * dot(d0, d0), 1e-5f);
}

TEST(DiffuseForces, SpiralTurnsAndDrawsInAndHelixTurnsAndRises) {
    const float rate = 1.5f, pull = 0.4f, rise = 0.2f;
    const Vec3f c{0, 1, 0}, d0{0.3f, 0.1f, 0};
    const float t = 90 * kDt;
    const float turn = rate * t;
    {
        Vec3f p = c + d0, v{};
        run({2, {0, 1, 0}, rate, pull}, c, {}, 90, p, v);
        // About +y the radial part turns counter-clockwise seen from above and shrinks by e^-pull t.
        const float r = 0.3f * std::exp(-pull * t);
        expect_near(p, c + Vec3f{r * std::cos(turn), 0.1f, -r * std::sin(turn)}, 1e-4f, "spiral");
    }
    {
        Vec3f p = c + d0, v{};
        run({4, {0, 1, 0}, rate, rise}, c, {}, 90, p, v);
        expect_near(p, c + Vec3f{0.3f * std::cos(turn), 0.1f + rise * t, -0.3f * std::sin(turn)}, 1e-4f,
                    "helix");
    }
}

// A one-row grid: voxel 0 active, voxel 1 outside the mesh; particles cross between them.
struct TwoVoxels {
    std::vector<float> x, y, z, vx, vy, vz;
    std::vector<std::uint32_t> id, voxel, from_rgba, to_rgba, dead, dead_count{0}, moves{0, 0}, move_count{0};
    std::vector<float> from_size, to_size, elapsed, duration;
    std::vector<DiffuseSprite> sprite{1};
    std::vector<std::uint32_t> depth_key{0};
    std::vector<std::uint16_t> material{0, kNoMaterial};
    std::vector<std::uint32_t> voxel_rgba{0x80ffffffu, 0};
    std::vector<std::uint16_t> column{0, 1};
    std::vector<std::uint32_t> density{1, 0};
    std::vector<VoxelMaterial> materials{1};
    std::vector<float> steps;

    explicit TwoVoxels(float x0, float vx0) {
        x = {x0}, y = {0.5f}, z = {0.5f}, vx = {vx0}, vy = {0}, vz = {0}, id = {0};
        voxel = {0}, from_rgba = to_rgba = {0x80ffffffu}, dead = {0};
        from_size = to_size = {0.05f}, elapsed = {0}, duration = {0.1f};
        VoxelMaterial& m = materials[0];
        m.lifetime = 0.5f, m.fade_rgba = 0, m.fade_size = 0.2f, m.drag = 0;
        m.step = make_voxel_step({}, 0, kDt);
    }
    DiffuseUpdateContext context() {
        DiffuseUpdateContext c;
        c.particles = {x, y, z, vx, vy, vz, id};
        c.attributes = {voxel, from_rgba, to_rgba, from_size, to_size, elapsed, duration, sprite, depth_key};
        c.grid = {{0, 0, 0}, 1, 2, 1, 1};
        c.material = material, c.voxel_rgba = voxel_rgba, c.materials = materials;
        c.column = column, c.density = density;
        c.dt = kDt, c.block_size = 1, c.dead = dead, c.dead_count = dead_count;
        c.moves = moves, c.move_count = move_count;
        steps = make_diffuse_step_table(materials, make_voxel_step({}, 0, kDt));
        c.steps = steps;
        return c;
    }
    int step() {
        const DiffuseUpdateContext c = context();
        diffuse_update_block(0, c);
        diffuse_apply_moves(c, 1);
        return int(dead_count[0]);
    }
};

TEST(DiffuseUpdate, LeavingFadesToTheLastVoxelsFadeAndDiesAfterItsLifetime) {
    TwoVoxels t(0.95f, 6.0f);  // into voxel 1 on the first step
    EXPECT_EQ(t.step(), 0);
    EXPECT_EQ(t.voxel[0], kOutsideVoxel) << "fading, outside the active voxels";
    EXPECT_EQ(t.density[0], 0u) << "the voxel lost its particle";
    EXPECT_EQ(t.to_rgba[0] >> 24, 0u) << "fades to the fade alpha";
    EXPECT_FLOAT_EQ(t.to_size[0], 0.2f);
    t.vx[0] = 0;
    int steps = 1;
    while (t.step() == 0 && steps < 1000) ++steps;
    // Dies on the step its fade (0.5 s = 30 steps, the step it left included) completes.
    EXPECT_EQ(steps + 1, 30);
    EXPECT_EQ(t.sprite[0].rgba >> 24, 0u) << "faded out completely";
    EXPECT_FLOAT_EQ(t.sprite[0].size, 0.2f);
}

TEST(DiffuseUpdate, ReenteringStopsTheFadeAndResetsTheLifetime) {
    TwoVoxels t(0.95f, 6.0f);
    t.step();
    ASSERT_EQ(t.voxel[0], kOutsideVoxel);
    t.vx[0] = 0;
    for (int i = 0; i < 20; ++i) ASSERT_EQ(t.step(), 0);  // most of the 30-step fade
    t.vx[0] = -6.0f;                                      // back into voxel 0
    t.step();
    EXPECT_EQ(t.voxel[0], 0u) << "no longer fading";
    EXPECT_EQ(t.density[0], 1u);
    EXPECT_EQ(t.to_rgba[0], 0x80ffffffu);
    t.vx[0] = 0;
    for (int i = 0; i < 300; ++i) ASSERT_EQ(t.step(), 0) << "alive inside an active voxel, step " << i;
    EXPECT_EQ(t.sprite[0].rgba, 0x80ffffffu);
}

// A birth's interpolation state is the update's to set: whatever the emission left in its place (here a
// dead particle's fade), a particle listed as born starts from transparent towards its voxel's colour.
TEST(DiffuseUpdate, ABirthStartsTransparentTowardsItsVoxelsColour) {
    TwoVoxels t(0.5f, 0.0f);
    t.from_rgba = {0x12345678u}, t.to_rgba = {0x00abcdefu}, t.from_size = {0.7f}, t.to_size = {0.9f};
    t.elapsed = {3}, t.duration = {0.25f};
    const std::vector<std::uint32_t> born{0};
    DiffuseUpdateContext c = t.context();
    c.born = born;
    diffuse_update_block(0, c);
    const VoxelMaterial& m = t.materials[0];
    EXPECT_EQ(t.to_rgba[0], 0x80ffffffu);
    EXPECT_EQ(t.from_rgba[0], 0x00ffffffu);
    EXPECT_FLOAT_EQ(t.to_size[0], m.size);
    EXPECT_FLOAT_EQ(t.duration[0], m.interpolation_time);
    EXPECT_FLOAT_EQ(t.elapsed[0], kDt) << "its first step";
    EXPECT_EQ(t.sprite[0].rgba, lerp_rgba(0x00ffffffu, 0x80ffffffu, kDt / m.interpolation_time));
}

// Two active voxels of one material: crossing into the one of the same colour leaves the particle's
// fade-in running; crossing into one of another colour starts a new interpolation from where it was.
TEST(DiffuseUpdate, AVoxelOfTheSameLookKeepsTheInterpolationAndAnotherStartsANewOne) {
    for (const bool same : {true, false}) {
        TwoVoxels t(0.95f, 6.0f);  // into voxel 1 on the first step
        t.material = {0, 0}, t.column = {0, 0};
        t.voxel_rgba = {0x80ffffffu, same ? 0x80ffffffu : 0x8000ff00u};
        t.from_rgba = {0x00ffffffu}, t.elapsed = {0.05f};  // half way through its fade-in
        ASSERT_EQ(t.step(), 0);
        EXPECT_EQ(t.voxel[0], 1u);
        EXPECT_EQ(t.density[0], 0u);
        EXPECT_EQ(t.density[1], 1u) << "the move is counted either way";
        if (same) {
            EXPECT_EQ(t.from_rgba[0], 0x00ffffffu) << "the same fade-in";
            EXPECT_FLOAT_EQ(t.elapsed[0], 0.05f + kDt) << "its clock runs on";
            EXPECT_EQ(t.sprite[0].rgba, lerp_rgba(0x00ffffffu, 0x80ffffffu, (0.05f + kDt) / 0.1f));
        } else {
            EXPECT_EQ(t.from_rgba[0], lerp_rgba(0x00ffffffu, 0x80ffffffu, 0.5f)) << "from where it was";
            EXPECT_EQ(t.to_rgba[0], 0x8000ff00u);
            EXPECT_FLOAT_EQ(t.elapsed[0], kDt) << "a new interpolation";
        }
        // Arrived within the interpolation time: the old one's 0.1 s, or the voxel's 0.3 s anew.
        t.vx[0] = 0;
        for (int i = 0; i < 18; ++i) ASSERT_EQ(t.step(), 0);
        EXPECT_EQ(t.sprite[0].rgba, t.voxel_rgba[1]);
        EXPECT_EQ(same, t.elapsed[0] < t.materials[0].interpolation_time);
    }
}

// Six voxels in a row: materials of every force kind (none, linear, spiral, orbit, helix; some about
// their region's centre, some about the voxel's) and one voxel outside the mesh. 37 particles fill whole
// vectors and a partial one; every particle must move exactly as apply_voxel_step moves it alone.
TEST(DiffuseUpdate, EveryLaneStepsAsTheScalarStepOfItsOwnMaterial) {
    constexpr std::size_t kParticles = 37;
    std::vector<VoxelMaterial> materials(5);
    for (std::uint8_t k = 0; k < 5; ++k) {
        VoxelMaterial& m = materials[k];
        m.force.kind = k;
        m.force.vector = k == 1 ? Vec3f{0.5f, -2.0f, 0.25f} : normalize(Vec3f{0.2f, 1.0f, 0.1f * k});
        m.force.rate = 1.5f + 0.5f * k;
        m.force.pull = 0.1f * k;
        m.about_region = k == 2;
        m.region_centre = {2.4f, 0.3f, 0.6f};
        m.drag = 0.5f * k;
        m.step = make_voxel_step(m.force, m.drag, kDt);
    }
    const std::vector<std::uint16_t> material{0, 1, 2, 3, 4, kNoMaterial};
    const std::vector<std::uint32_t> voxel_rgba(6, 0xff808080u);
    const std::vector<std::uint16_t> column{0, 1, 2, 3, 4, 5};
    std::vector<std::uint32_t> density(6, 100);
    std::vector<float> x, y, z, vx, vy, vz, from_size, to_size, elapsed, duration;
    std::vector<std::uint32_t> id, voxel, from_rgba, to_rgba, dead(64), dead_count(1), moves(128),
        move_count(1), depth_key(kParticles);
    for (std::size_t i = 0; i < kParticles; ++i) {
        const float u = float(i % 7) / 7.0f, w = float(i % 5) / 5.0f;
        const std::uint32_t cell = std::uint32_t(i % 6);
        x.push_back(float(cell) + 0.1f + 0.8f * u), y.push_back(0.2f + 0.6f * w),
            z.push_back(0.5f + 0.3f * u - 0.2f * w);
        vx.push_back(0.3f * w - 0.1f), vy.push_back(0.2f * u), vz.push_back(-0.15f * u * w);
        id.push_back(std::uint32_t(i)), voxel.push_back(cell == 5 ? kOutsideVoxel : cell);
        from_rgba.push_back(0xff808080u), to_rgba.push_back(0xff808080u);
        from_size.push_back(0.05f), to_size.push_back(0.05f), elapsed.push_back(1), duration.push_back(0.1f);
    }
    std::vector<DiffuseSprite> sprite(kParticles);
    const Vec3f accel{0.0f, -0.8f, 0.1f}, offset{0.01f, -0.02f, 0.0f};
    const VoxelStep outside = make_voxel_step({}, 0, kDt);
    const std::vector<float> steps = make_diffuse_step_table(materials, outside);
    DiffuseUpdateContext c;
    c.grid = {{0, 0, 0}, 1, 6, 1, 1};
    c.offset = offset;
    c.material = material, c.voxel_rgba = voxel_rgba, c.materials = materials;
    c.column = column, c.density = density, c.steps = steps;
    c.accel = accel, c.dt = kDt, c.block_size = 64, c.dead = dead, c.dead_count = dead_count;
    c.moves = moves, c.move_count = move_count;
    c.depth_map = {{-1.0f, 2.0f, 3.0f}, normalize(Vec3f{0.6f, -0.3f, -0.5f}), 0.5f, 5.0f};
    const std::vector<float> x0 = x, y0 = y, z0 = z, vx0 = vx, vy0 = vy, vz0 = vz;
    c.particles = {x, y, z, vx, vy, vz, id};
    c.attributes = {voxel, from_rgba, to_rgba, from_size, to_size, elapsed, duration, sprite, depth_key};
    diffuse_update_block(0, c);
    for (std::size_t i = 0; i < kParticles; ++i) {
        const std::uint32_t cell = std::uint32_t(i % 6);
        Vec3f p{x0[i], y0[i], z0[i]}, v{vx0[i], vy0[i], vz0[i]};
        if (cell == 5) {
            apply_voxel_step(outside, {}, accel, p, v);
        } else {
            const VoxelMaterial& m = materials[cell];
            const Vec3f centre = m.force.kind < 2 ? Vec3f{}
                                 : m.about_region ? m.region_centre + offset
                                                  : c.grid.voxel_centre(cell) + offset;
            apply_voxel_step(m.step, centre, accel, p, v);
        }
        // Bit for bit: the lanes do the scalar step's operations in its order.
        EXPECT_EQ(x[i], p.x) << "particle " << i << ", voxel " << cell;
        EXPECT_EQ(y[i], p.y) << "particle " << i;
        EXPECT_EQ(z[i], p.z) << "particle " << i;
        EXPECT_EQ(vx[i], v.x) << "particle " << i;
        EXPECT_EQ(vy[i], v.y) << "particle " << i;
        EXPECT_EQ(vz[i], v.z) << "particle " << i;
        EXPECT_EQ(sprite[i].x, p.x) << "particle " << i;
        EXPECT_EQ(depth_key[i], c.depth_map.key(p.x, p.y, p.z)) << "particle " << i;
        EXPECT_EQ(voxel[i], c.grid.voxel_of(p - offset) < 5 ? c.grid.voxel_of(p - offset) : kOutsideVoxel);
    }
}

TEST(DiffuseUpdate, DeadAreFilledFromTheEndInAFixedOrder) {
    std::vector<int> v{0, 1, 2, 3, 4, 5, 6, 7};
    const std::vector<std::uint32_t> dead{1, 4, 6, 7};
    const std::size_t n =
        fill_dead_from_end(v.size(), dead, [&](std::size_t from, std::size_t to) { v[to] = v[from]; });
    ASSERT_EQ(n, 4u);
    EXPECT_EQ(std::vector<int>(v.begin(), v.begin() + 4), (std::vector<int>{0, 5, 2, 3}));
}

// A small box-shaped object that fills fast: 10^3 voxels.
SceneDesc box_scene() {
    SceneDesc s = make_builtin_scene("ghost");
    s.name = "box test";
    s.max_particles = 20000;
    s.warmup_frames = 0;
    s.diffuse.mesh = "box";
    s.diffuse.scale = 1;
    s.diffuse.resolution = 10;
    s.diffuse.regions.clear();
    s.diffuse.colliders.clear();
    s.container_motion = {};
    s.diffuse.defaults = {};
    s.diffuse.defaults.max_density = 5;
    s.diffuse.defaults.fill_time = 0.1f;
    s.diffuse.defaults.jitter = 0.3f;
    return s;
}

// Particles per voxel, counted from their positions.
std::vector<std::uint32_t> count_per_voxel(const DiffuseSimulation& d, const ParticleSet& p) {
    std::vector<std::uint32_t> n(d.density().size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const std::uint32_t v = d.grid().voxel_of(Vec3f{p.x()[i], p.y()[i], p.z()[i]} - d.object_offset());
        if (v != kOutsideVoxel && d.object().material[v] != kNoMaterial) ++n[v];
    }
    return n;
}

TEST(DiffuseSimulation, EmissionFillsEveryVoxelUpToItsMaximumDensityAndNoFurther) {
    SceneDesc still = box_scene();
    still.diffuse.defaults.jitter = 0;  // particles stay where they are born
    SceneSimulation sim(still);
    const DiffuseSimulation& d = *sim.diffuse();
    const std::size_t inside = d.object().inside.size();
    EXPECT_EQ(inside, 1000u) << "a unit box at 10 voxels a side";
    for (int f = 0; f < 40; ++f) {
        sim.step_serial(1);
        for (std::uint32_t v : d.object().inside) ASSERT_LE(d.density()[v], 5u) << "frame " << f;
    }
    const std::vector<std::uint32_t> n = count_per_voxel(d, sim.particles());
    for (std::uint32_t v : d.object().inside) ASSERT_EQ(n[v], 5u) << "every voxel full, none over";
    EXPECT_EQ(sim.particles().size(), 5000u);
}

TEST(DiffuseSimulation, DensityCountsTheParticlesInEachVoxelWhileTheyMove) {
    SceneSimulation sim(box_scene());  // jitter: particles wander between voxels
    const DiffuseSimulation& d = *sim.diffuse();
    for (int f = 0; f < 60; ++f) {
        sim.step_serial(1);
        const std::vector<std::uint32_t> n = count_per_voxel(d, sim.particles());
        for (std::uint32_t v : d.object().inside) ASSERT_EQ(d.density()[v], n[v]) << "frame " << f;
    }
}

TEST(DiffuseSimulation, NoParticleEverInsideAStaticOrMovingSolid) {
    SceneDesc s = box_scene();
    s.diffuse.defaults.force = "spiral";
    s.diffuse.defaults.force_vector = {0, 0, 1};
    s.diffuse.defaults.force_rate = 3;
    s.diffuse.defaults.about_region = true;
    s.diffuse.defaults.jitter = 1.0f;
    s.diffuse.defaults.drag = 0;
    DiffuseCollider still;
    still.shape = "sphere", still.radius = 0.2f, still.from = {0.1f, 0.5f, 0};
    DiffuseCollider moving;
    moving.shape = "box", moving.half_extents = {0.1f, 0.3f, 0.1f};
    moving.from = {-0.9f, 0.5f, 0.2f}, moving.to = {0.9f, 0.5f, 0.2f}, moving.period = 1.0f;
    s.diffuse.colliders = {still, moving};
    SceneSimulation sim(s);
    const DiffuseSimulation& d = *sim.diffuse();
    for (int f = 0; f < 120; ++f) {
        sim.step_serial(1);
        const ParticleSet& p = sim.particles();
        for (std::size_t c = 0; c < 2; ++c)
            for (std::size_t i = 0; i < p.size(); ++i)
                ASSERT_FALSE(
                    d.collider(c).contains(Vec3f{p.x()[i], p.y()[i], p.z()[i]} - d.collider_centre(c)))
                    << "particle " << i << " inside collider " << c << " after frame " << f << " at "
                    << p.x()[i] << "," << p.y()[i] << "," << p.z()[i] << " id " << p.id()[i];
    }
    // The voxels the still sphere covers never emit: none of them holds a particle.
    const std::vector<std::uint32_t> n = count_per_voxel(d, sim.particles());
    const std::uint32_t centre_voxel = d.grid().voxel_of(still.from);
    EXPECT_TRUE(d.blocked(centre_voxel));
    EXPECT_EQ(n[centre_voxel], 0u);
}

// The staged sprites of a frame, run through the pipeline without rendering.
std::vector<FrameRecord> run_scene(const SceneDesc& s, int threads, int frames,
                                   Recording* recording = nullptr) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, std::size_t(threads));
    PipelineSettings config;
    config.method = SurfaceMethod::kSprites;
    config.render = false;
    config.hash_frames = true;
    FramePipeline p(s, config);
    p.warmup();
    p.run(frames);
    if (recording) {
        std::vector<FrameInputs> inputs;
        for (std::uint64_t f = 0; f < std::uint64_t(s.warmup_frames + frames); ++f)
            inputs.push_back(scripted_inputs(s, f));
        *recording = make_recording(p, inputs);
    }
    return p.records();
}

std::vector<FrameRecord> run_ghost(int threads, int frames, Recording* recording = nullptr) {
    SceneDesc s = make_builtin_scene("ghost");
    s.max_particles = 12000;
    s.warmup_frames = 5;
    s.diffuse.resolution = 24;
    s.diffuse.colliders[0].period = 0.5f;  // through the body within the test's frames
    return run_scene(s, threads, frames, recording);
}

// A wall sweeping through a dense box of particles that fade out within a frame or two: thousands die
// and are born every frame, the births in the dead's places and the copies of the compaction (where
// fewer are born than die) across several blocks.
SceneDesc churning_scene() {
    SceneDesc s = box_scene();
    s.max_particles = 40000;
    s.diffuse.resolution = 20;
    s.diffuse.defaults.fill_time = 0.05f;
    s.diffuse.defaults.lifetime = 0.03f;
    DiffuseCollider wall;
    wall.shape = "box", wall.half_extents = {0.25f, 0.7f, 0.7f};
    wall.from = {-0.9f, 0.5f, 0.0f}, wall.to = {0.9f, 0.5f, 0.0f}, wall.period = 0.4f;
    s.diffuse.colliders = {wall};
    return s;
}

TEST(DiffusePipeline, ChurnFillsSeveralBlocksWithTheSameBytesAtOneAndTwoThreads) {
    const SceneDesc s = churning_scene();
    // Serially: how many die a frame (ids gone by the next frame), and the density stays exact.
    SceneSimulation sim(s);
    const DiffuseSimulation& d = *sim.diffuse();
    std::map<std::uint32_t, std::size_t> place;  // id -> index, the frame before
    std::size_t most_dead = 0, frames_in_place = 0;
    for (int f = 0; f < 40; ++f) {
        const std::size_t count = sim.particles().size();
        sim.step_serial(1);
        const ParticleSet& p = sim.particles();
        const std::set<std::uint32_t> now(p.id().begin(), p.id().end());
        ASSERT_EQ(now.size(), p.size()) << "an id twice after frame " << f;
        std::size_t dead = 0;
        for (const auto& [id, index] : place) dead += !now.count(id);
        most_dead = std::max(most_dead, dead);
        // As many born as died: the births took the dead's places and no survivor moved.
        if (dead > 0 && p.size() == count) {
            ++frames_in_place;
            for (std::size_t i = 0; i < p.size(); ++i) {
                const auto it = place.find(p.id()[i]);
                if (it != place.end()) {
                    ASSERT_EQ(it->second, i) << "a survivor moved, frame " << f;
                }
            }
        }
        place.clear();
        for (std::size_t i = 0; i < p.size(); ++i) place[p.id()[i]] = i;
        // Particles under the wall count for no voxel: theirs is switched off.
        const std::vector<std::uint32_t> n = count_per_voxel(d, p);
        for (std::uint32_t v : d.object().inside)
            ASSERT_EQ(d.density()[v], d.blocked(v) ? 0u : n[v]) << "frame " << f;
    }
    EXPECT_GT(most_dead, 3u * 4096u) << "the births and copies should span several blocks";
    EXPECT_GT(frames_in_place, 5u) << "frames with as many births as deaths";
    const std::vector<FrameRecord> one = run_scene(s, 1, 40), two = run_scene(s, 2, 40);
    ASSERT_EQ(one.size(), two.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
        ASSERT_EQ(one[i].particle_hash, two[i].particle_hash) << "frame " << i;
        ASSERT_EQ(one[i].hash, two[i].hash) << "frame " << i;
    }
}

// A frame's sprites are final after the update, before the births and copies that close the gaps: each
// drawn one (alpha above zero) is a particle alive at the frame's end, where it is, and every particle
// that lived through the frame is drawn. The dead fade to a visible alpha here, so a dead one's sprite
// would show if it were not made transparent.
TEST(DiffusePipeline, EachFramesSpritesAreItsLivingParticlesAndNoDeadOne) {
    SceneDesc s = churning_scene();
    s.diffuse.defaults.fade_alpha = 0.5f;
    SceneSimulation sim(s);
    const DiffuseSimulation& d = *sim.diffuse();
    using Place = std::array<float, 3>;
    std::set<std::uint32_t> before;
    std::size_t frames_with_copies = 0, dead_seen = 0;
    for (int f = 0; f < 40; ++f) {
        const std::size_t count = sim.particles().size();
        sim.step_serial(1);
        const ParticleSet& p = sim.particles();
        const std::span<const DiffuseSprite> sprites = d.sprites();
        ASSERT_EQ(sprites.size(), count) << "one sprite for each particle the update stepped";
        ASSERT_EQ(d.depth_keys().size(), count);
        std::map<Place, std::uint32_t> alive;  // place -> id
        for (std::size_t i = 0; i < p.size(); ++i) alive[{p.x()[i], p.y()[i], p.z()[i]}] = p.id()[i];
        std::set<Place> drawn_at;
        for (const DiffuseSprite& q : sprites) {
            const auto it = alive.find({q.x, q.y, q.z});
            drawn_at.insert({q.x, q.y, q.z});
            if ((q.rgba >> 24) == 0) {
                dead_seen += it == alive.end();
                continue;
            }
            ASSERT_NE(it, alive.end()) << "a visible sprite of no living particle, frame " << f;
            ASSERT_TRUE(before.count(it->second)) << "a birth visible in its first frame, frame " << f;
        }
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (!before.count(p.id()[i])) continue;
            ASSERT_TRUE(drawn_at.count({p.x()[i], p.y()[i], p.z()[i]}))
                << "particle " << p.id()[i] << " lived through frame " << f << " but has no sprite";
        }
        frames_with_copies += p.size() < count;
        before = std::set<std::uint32_t>(p.id().begin(), p.id().end());
    }
    EXPECT_GT(dead_seen, 1000u) << "the dead's sprites are there, transparent";
    EXPECT_GT(frames_with_copies, 0u) << "frames that moved particles into the gaps";
}

TEST(DiffusePipeline, SameBytesAtOneAndTwoThreadsAndReplayedFromARecording) {
    Recording rec;
    const std::vector<FrameRecord> one = run_ghost(1, 24, &rec);
    const std::vector<FrameRecord> two = run_ghost(2, 24);
    ASSERT_EQ(one.size(), two.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
        EXPECT_EQ(one[i].particle_hash, two[i].particle_hash) << "frame " << i;
        EXPECT_EQ(one[i].hash, two[i].hash) << "frame " << i;
        EXPECT_EQ(one[i].particles, two[i].particles);
    }
    EXPECT_GT(one.back().particles, 1000u);
    const std::string path = test::temp_path("ghost.rivrec");
    write_recording(path, rec);
    const Recording back = read_recording(path);
    EXPECT_EQ(back.method, SurfaceMethod::kSprites);
    EXPECT_EQ(scene_to_json(back.scene), scene_to_json(rec.scene));
    EXPECT_FALSE(first_divergence(back, two).has_value());
}

TEST(DiffusePipeline, SpritesAreStagedWithTheirBackToFrontOrder) {
    SceneDesc s = make_builtin_scene("ghost");
    s.max_particles = 8000;
    s.warmup_frames = 20;
    s.diffuse.resolution = 20;
    PipelineSettings config;
    config.method = SurfaceMethod::kSprites;
    config.render = false;
    FramePipeline p(s, config);
    p.warmup();
    p.run(2);
    FrameView view;
    p.surface().fill_view(1, view);
    const auto sprites = view.diffuse.sprites;
    const auto order = view.diffuse.order;
    ASSERT_GT(sprites.size(), 1000u);
    ASSERT_EQ(order.size(), sprites.size());
    std::vector<bool> seen(sprites.size(), false);
    for (const std::uint32_t k : order) {
        ASSERT_LT(k, sprites.size());
        ASSERT_FALSE(seen[k]) << "index " << k << " twice";
        seen[k] = true;
    }
    const Vec3f eye = s.camera.eye, dir = normalize(s.camera.target - eye);
    const auto depth = [&](const DiffuseSprite& q) { return dot(Vec3f{q.x, q.y, q.z} - eye, dir); };
    // Within one key step: 16 bits over the surface's 8 m depth window, 0.12 mm.
    const float key_step = 8.0f / float(kDepthKeyMax + 1u);
    for (std::size_t i = 1; i < order.size(); ++i)
        ASSERT_GE(depth(sprites[order[i - 1]]) + key_step, depth(sprites[order[i]])) << "sprite " << i;
}

TEST(DiffuseScenes, EveryBuiltInDiffuseSceneRunsAndTheFireIsOneVoxel) {
    for (const char* name : {"ghost", "dissolve", "fire", "bunny"}) {
        SceneDesc s = make_builtin_scene(name);
        s.warmup_frames = 0;
        SceneSimulation sim(s);
        sim.step_serial(10);
        EXPECT_GT(sim.particles().size(), 0u) << name;
        if (std::string(name) == "fire") {
            EXPECT_EQ(sim.diffuse()->object().inside.size(), 1u);
        }
    }
}

TEST(DiffuseScenes, SceneFilesRoundTripAndBadValuesAreNamed) {
    const SceneDesc ghost = make_builtin_scene("ghost");
    EXPECT_EQ(scene_to_json(scene_from_json(scene_to_json(ghost), "roundtrip")), scene_to_json(ghost));
    const auto error = [](const std::string& text) {
        try {
            scene_from_json(nlohmann::json::parse(text), "f.json");
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"resolution": 300}})").find("resolution"),
              std::string::npos);
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"defaults": {"force": "vortex"}}})").find("vortex"),
              std::string::npos);
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"defaults": {"alpha": 2}}})").find("alpha"),
              std::string::npos);
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"colliders": [{"shape": "cone"}]}})").find("shape"),
              std::string::npos);
    // -1 is how a file says "the default" (and how scene_to_json writes an unset attribute); any other
    // negative value, or a colour with only some components unset, is a mistake and not the default.
    EXPECT_EQ(
        error(R"({"base": "ghost", "diffuse": {"defaults": {"max_density": -1, "color": [-1, -1, -1]}}})"),
        "no error");
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"defaults": {"max_density": -3}}})")
                  .find("f.json.diffuse.defaults.max_density: must not be negative"),
              std::string::npos);
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"regions": [{"attributes": {"lifetime": -0.5}}]}})")
                  .find("regions[0].attributes.lifetime: must not be negative"),
              std::string::npos);
    EXPECT_NE(error(R"({"base": "ghost", "diffuse": {"defaults": {"fade_color": [-1, 0.5, 0]}}})")
                  .find("defaults.fade_color: colour components must be in [0, 1]"),
              std::string::npos);
}

TEST(DiffuseScenes, AnOpenMeshIsAClearError) {
    const std::string path = test::temp_path("open.obj");
    test::write_text(path,
                     "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");  // no fourth face
    SceneDesc s = make_builtin_scene("ghost");
    s.diffuse.mesh = path;
    try {
        SceneSimulation sim(s);
        FAIL() << "an open mesh was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace rivulet
