// SPH fluid (systems/sim/sph_simulation.h), both pressure solvers: determinism at 1 and 2 threads, any
// chunk schedule and the serial path; no allocation per frame; fluid at rest in a tank stays at rest
// (WCSPH) and at rest density, in the tank and at its rest height for 10 s (DFSPH); the dam break surge
// front against Martin & Moyce (1952); the moved container pushes the fluid; the built-in scenes run.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <tuple>
#include <vector>

#include "jobs/mesh_hash.h"
#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"

#include "support/counting_new.h"

namespace rivulet {
namespace {

std::uint64_t state_hash(const ParticleSet& ps) {
    Hasher h;
    h.add(ps.x()), h.add(ps.y()), h.add(ps.z());
    h.add(ps.vx()), h.add(ps.vy()), h.add(ps.vz());
    h.add(ps.id());
    return h.digest();
}

bool all_finite(const ParticleSet& ps) {
    for (std::span<const float> a : {ps.x(), ps.y(), ps.z(), ps.vx(), ps.vy(), ps.vz()}) {
        for (float v : a) {
            if (!std::isfinite(v)) return false;
        }
    }
    return true;
}

float max_speed(const ParticleSet& ps) {
    float v2 = 0;
    for (std::size_t i = 0; i < ps.size(); ++i) {
        v2 = std::max(v2, ps.vx()[i] * ps.vx()[i] + ps.vy()[i] * ps.vy()[i] + ps.vz()[i] * ps.vz()[i]);
    }
    return std::sqrt(v2);
}

class SphSolverTest : public ::testing::TestWithParam<SphSolver> {};

TEST_P(SphSolverTest, ChunkScheduleDoesNotChangeTheBytes) {
    SphDesc desc = make_dambreak(800);
    desc.solver = GetParam();
    const std::size_t n = sph_seed_count(desc);
    SphSimulation a(desc, n, 5), b(desc, n, 5);
    ParticleSet pa(n), pb(n);
    a.seed(pa), b.seed(pb);
    for (std::uint64_t f = 0; f < 10; ++f) {
        a.step_serial(pa, f);
        // b: every parallel phase's chunks in reverse order.
        b.begin_frame(pb, f);
        for (std::size_t p = b.next_phase(); p != SphSimulation::kPhaseCount; p = b.next_phase()) {
            const std::size_t chunks = b.phases()[p].parallel ? b.chunks() : 1;
            for (std::size_t c = chunks; c-- > 0;) b.run_phase(p, c, pb);
        }
        b.end_frame(pb);
        ASSERT_EQ(state_hash(pa), state_hash(pb)) << "frame " << f;
    }
}

TEST_P(SphSolverTest, TwoHundredFramesIdenticalAtOneAndTwoThreadsAndSerial) {
    // The slosh scene's moving tank, plus a user offset from frame 100: 200 frames, hashed every 50
    // (threads 0: the serial path).
    const auto hashes = [](int threads) {
        SphDesc desc = make_slosh(300);
        desc.solver = GetParam();
        const std::size_t n = sph_seed_count(desc);
        SphSimulation sim(desc, n, 8);
        ParticleSet ps(n);
        sim.seed(ps);
        std::vector<std::uint64_t> out;
        tbb::task_arena arena(std::max(threads, 1));
        for (std::uint64_t f = 0; f < 200; ++f) {
            if (f == 100) sim.set_container_offset({0.0f, 0.0f, 0.02f});
            if (threads == 0) {
                sim.step_serial(ps, f);
            } else {
                arena.execute([&] { sim.step_parallel(ps, f); });
            }
            if (f % 50 == 49) out.push_back(state_hash(ps));
        }
        EXPECT_TRUE(all_finite(ps));
        return out;
    };
    const auto one = hashes(1);
    EXPECT_EQ(one, hashes(2));
    EXPECT_EQ(one, hashes(0));
}

TEST(SphSim, SeedIsALatticeWithIdsInOrderAndFramesKeepEveryId) {
    const SphDesc desc = make_dambreak(2000);
    const std::size_t n = sph_seed_count(desc);
    EXPECT_GT(n, 1500u);
    EXPECT_LT(n, 2600u);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    ASSERT_EQ(ps.size(), n);
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(ps.id()[i], i);
    for (std::uint64_t f = 0; f < 5; ++f) sim.step_serial(ps, f);
    std::vector<std::uint32_t> ids(ps.id().begin(), ps.id().end());
    std::sort(ids.begin(), ids.end());
    for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(ids[i], i);
    const BoxCollider t = sim.tank();
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_GE(ps.x()[i], t.min.x);
        ASSERT_LE(ps.x()[i], t.max.x);
        ASSERT_GE(ps.y()[i], t.min.y);
    }
}

// The reference dam break (SPlisHSPlasH's DamBreakModel geometry, bench_sph --scene reference): 24,389
// particles are its 29^3 lattice filling the 1 m cube column, which stands off the floor, the left wall and
// both side walls.
TEST(SphSim, TheReferenceDamBreakIsATwentyNineCubedColumn) {
    const SphDesc desc = make_dambreak_reference();
    EXPECT_NEAR(desc.spacing, 1.0f / 29.0f, 1e-6f);
    const std::size_t n = sph_seed_count(desc);
    ASSERT_EQ(n, 24389u);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (std::size_t i = 0; i < n; ++i) {
        const float p[3] = {ps.x()[i], ps.y()[i], ps.z()[i]};
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
    const float d = desc.spacing;
    const float column_lo[3] = {0.05f, 0.05f, 0.25f};
    for (int a = 0; a < 3; ++a) {  // the lattice's outer centres half a spacing inside the column
        EXPECT_NEAR(lo[a], column_lo[a] + 0.5f * d, 1e-4f) << "axis " << a;
        EXPECT_NEAR(hi[a], column_lo[a] + 1.0f - 0.5f * d, 1e-4f) << "axis " << a;
    }
    const BoxCollider t = sim.tank();
    EXPECT_FLOAT_EQ(t.max.x - t.min.x, 4.0f);
    EXPECT_FLOAT_EQ(t.max.y - t.min.y, 3.0f);
    EXPECT_FLOAT_EQ(t.max.z - t.min.z, 1.5f);
}

TEST(SphSim, SteadyStateFramesDoNotAllocate) {
    const SphDesc desc = make_drop(1500);
    const std::size_t n = sph_seed_count(desc);
    SphSimulation sim(desc, n, 4);
    ParticleSet ps(n);
    sim.seed(ps);
    sim.step_serial(ps, 0);
    const long before = test::allocation_count();
    for (std::uint64_t f = 1; f < 4; ++f) sim.step_serial(ps, f);
    EXPECT_EQ(test::allocation_count(), before);
}

TEST(SphSim, RejectsBadDescAndTooManyParticles) {
    SphDesc bad = make_dambreak(500);
    bad.spacing = 0;
    EXPECT_THROW(SphSimulation(bad, 10), std::invalid_argument);
    for (const float rho : {-0.1f, 1.0f, std::numeric_limits<float>::quiet_NaN()}) {
        SphDesc chebyshev = make_dambreak(500);
        chebyshev.chebyshev = rho;
        EXPECT_NE(sph_desc_problem(chebyshev, 1000).find("sph.chebyshev must be in [0, 0.99]"),
                  std::string::npos)
            << rho;
    }
    SphDesc cfl = make_dambreak(500);
    cfl.cfl = -1;
    EXPECT_NE(sph_desc_problem(cfl, 1000).find("sph.cfl must be in [0, 10]"), std::string::npos);
    // The fluid is counted before anything is allocated: 385 lattice points do not fit 10 particles.
    const SphDesc ok = make_dambreak(500);
    try {
        SphSimulation sim(ok, 10);
        ADD_FAILURE() << "a fluid over max_particles was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("needs 385 particles but max_particles is 10"),
                  std::string::npos)
            << e.what();
    }
}

// A block of water 0.15 x 0.1 x 0.1 m (spacing 1.25 cm, h = 2.5 cm, 768 particles) in a closed tank
// 0.3 m high, released from the lattice.
constexpr float kRestDepth = 0.1f;
SphDesc resting_block(SphSolver solver) {
    SphDesc desc;
    desc.name = "rest";
    desc.solver = solver;
    desc.spacing = 0.0125f;
    desc.container.box = {{0, 0, 0}, {0.15f, 0.3f, 0.1f}};
    desc.fluid_boxes.push_back({{0, 0, 0}, {0.15f, kRestDepth, 0.1f}, {}});
    return desc;
}

// The weakly compressible fluid: after 2 s of simulated time at rest and at rest density.
TEST(SphSim, FluidAtRestInATankStaysAtRest) {
#if defined(__SANITIZE_THREAD__)
    // A physics check (hundreds of steps of one small scene): ThreadSanitizer would only watch the SPH
    // jobs' threads again, which TwoHundredFramesIdenticalAtOneAndTwoThreadsAndSerial and
    // BuiltInScenesRunAndStayFinite already run under it.
    GTEST_SKIP() << "physics check, no thread coverage of its own";
#endif
    SphDesc desc = resting_block(SphSolver::kWcsph);
    const float depth = kRestDepth;
    desc.sound_speed = 10.0f * std::sqrt(2.0f * 9.81f * depth);
    desc.max_substeps = 100;
    const std::size_t n = sph_seed_count(desc);
    ASSERT_EQ(n, 768u);
    SphSimulation sim(desc, n, 4);
    ParticleSet ps(n);
    sim.seed(ps);
    for (std::uint64_t f = 0; f < 120; ++f) sim.step_serial(ps, f);  // 2 s at 60 frames/s
    ASSERT_NEAR(sim.time(), 2.0, 1e-6);
    ASSERT_TRUE(all_finite(ps));

    // Speeds: no flow left, next to the free-fall speed of the column sqrt(2 g depth) = 1.4 m/s: the largest
    // under 5 % of it, the RMS under 1 % (a weakly compressible fluid keeps some acoustic noise).
    const float vmax = max_speed(ps);
    double v2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
        v2 += double(ps.vx()[i]) * ps.vx()[i] + double(ps.vy()[i]) * ps.vy()[i] +
              double(ps.vz()[i]) * ps.vz()[i];
    }
    const double vrms = std::sqrt(v2 / double(n));
    EXPECT_LT(vmax, 0.05f * std::sqrt(2.0f * 9.81f * depth)) << "max speed " << vmax;
    EXPECT_LT(vrms, 0.01 * std::sqrt(2.0 * 9.81 * depth)) << "rms speed " << vrms;
    // Density: every particle more than h below the free surface (where the kernel support is full of
    // fluid or wall) within 3 % of rest density.
    const auto y = ps.y();
    const float top = *std::max_element(y.begin(), y.end());
    float worst = 0;
    double mean = 0;
    std::size_t inner = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (y[i] > top - sim.support()) continue;
        const float err = std::abs(sim.density()[i] / desc.rest_density - 1.0f);
        worst = std::max(worst, err);
        mean += sim.density()[i];
        ++inner;
    }
    ASSERT_GT(inner, n / 2);
    EXPECT_LT(worst, 0.03f) << "worst density error below the surface";
    EXPECT_NEAR(mean / double(inner), desc.rest_density, 0.03 * desc.rest_density);
    // The column keeps its height (no collapse into the walls): top particle within one spacing.
    EXPECT_NEAR(top, depth - 0.5f * desc.spacing, desc.spacing);
    std::printf(
        "rest: max speed %.4f m/s, rms speed %.4f m/s, worst density error %.4f, mean density %.2f, top %.4f "
        "m\n",
        vmax, vrms, worst, mean / double(inner), top);
}

// The same block with the incompressible solver, for 10 s: every frame's density error within the set
// bound, every particle inside the tank on every frame, and the free surface near the analytic rest
// height (the column's volume over the tank's floor, 0.1 m): the top particles' centres plus half a
// spacing, away from the walls, within 5 %. It settles 3.4-4.5 % low: the top layer, short of neighbours,
// reads under rest density until it has closed in on the layer below by about 0.3 spacings (the
// particle-deficiency of any SPH density estimate at a free surface; docs/sph.md). Where in that range
// depends on the packing the 768 particles settle into, which rounding alone changes: three orders of the
// list build's sums gave 3.4, 3.6 and 4.5 %.
TEST(SphSim, DfsphTankHoldsRestDensityAndHeightForTenSeconds) {
#if defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "physics check, no thread coverage of its own";
#endif
    const SphDesc desc = resting_block(SphSolver::kDfsph);
    const float depth = kRestDepth;
    const std::size_t n = sph_seed_count(desc);
    ASSERT_EQ(n, 768u);
    SphSimulation sim(desc, n, 4);
    ParticleSet ps(n);
    sim.seed(ps);
    const BoxCollider tank = desc.container.box;
    double worst_error = 0;
    for (std::uint64_t f = 0; f < 600; ++f) {
        sim.step_serial(ps, f);
        ASSERT_LE(sim.density_error(), 0.01 * desc.max_density_error + 1e-6) << "frame " << f;
        ASSERT_LT(sim.density_iterations(), desc.max_iterations * sim.substeps()) << "frame " << f;
        worst_error = std::max(worst_error, sim.density_error());
        for (std::size_t i = 0; i < n; ++i) {
            const Vec3f p{ps.x()[i], ps.y()[i], ps.z()[i]};
            ASSERT_TRUE(p.x >= tank.min.x && p.x <= tank.max.x && p.y >= tank.min.y && p.y <= tank.max.y &&
                        p.z >= tank.min.z && p.z <= tank.max.z)
                << "particle " << ps.id()[i] << " left the tank at frame " << f;
        }
    }
    ASSERT_TRUE(all_finite(ps));
    // The surface: the mean of the highest particle per column of the lattice, over columns one kernel
    // radius from the walls.
    const float d = desc.spacing, h = sim.support();
    std::vector<float> top(12 * 8, 0.0f);
    for (std::size_t i = 0; i < n; ++i) {
        const float x = ps.x()[i], z = ps.z()[i];
        if (x < h || x > tank.max.x - h || z < h || z > tank.max.z - h) continue;
        const std::size_t cell = std::size_t(z / d) * 12 + std::size_t(x / d);
        top[cell] = std::max(top[cell], ps.y()[i]);
    }
    double sum = 0;
    int columns = 0;
    for (float t : top)
        if (t > 0) sum += t, ++columns;
    ASSERT_GT(columns, 10);
    const double surface = sum / columns + 0.5 * d;
    EXPECT_NEAR(surface, depth, 0.05 * depth);
    std::printf("DFSPH rest, 10 s: surface %.4f m (rest height %.4f), worst density error %.4f %%\n", surface,
                depth, 100.0 * worst_error);
}

// Martin, J. C. & Moyce, W. J. (1952), "An experimental study of the collapse of liquid columns on a rigid
// horizontal plane", Phil. Trans. R. Soc. A 244, 312-324, Figure 3, n^2 = 2 (column height 2a), a = 2.25 in;
// digitised in PySPH, pysph/examples/db_exp_data.py (mm_data_2): surge front Z / a against
// T = t sqrt(2 g / a). The points below are the first seven of that series, before the front reaches the
// end of our tank (8a).
struct FrontPoint {
    double T, Z;
};
constexpr FrontPoint kMartinMoyce[] = {{1.219, 1.474}, {1.997, 2.292}, {2.547, 2.995}, {3.345, 4.134},
                                       {4.034, 4.944}, {4.418, 5.881}, {5.091, 6.980}};

// Quasi-2D dam break: column a = 0.1 m wide, 2a high, 16 particles across (spacing 6.25 mm, h = 1.25 cm),
// 4 particle layers between free-slip side walls (2,048 particles), tank 8a long. The front is the leading
// edge of the surge on the floor: the 9th largest x of any particle (the leading few are single droplets
// the incompressible solver throws ahead of the sheet; the photographs show the sheet's edge), sampled
// every 5 ms and interpolated linearly in time.
constexpr std::size_t kFrontRank = 8;
// (At 20 across, 3,200 particles, the errors are within 2 points of these and also pass.)
TEST_P(SphSolverTest, DamBreakFrontFollowsMartinMoyce) {
#if defined(__SANITIZE_THREAD__)
    // A physics check (hundreds of steps of one small scene): ThreadSanitizer would only watch the SPH
    // jobs' threads again, which TwoHundredFramesIdenticalAtOneAndTwoThreadsAndSerial and
    // BuiltInScenesRunAndStayFinite already run under it.
    GTEST_SKIP() << "physics check, no thread coverage of its own";
#endif
    const float a = 0.1f;
    SphDesc desc = make_dambreak_slab(a, 16, 4);
    desc.solver = GetParam();
    desc.container.box.max.x = 8.0f * a;
    desc.dt = 0.005f;
    const std::size_t n = sph_seed_count(desc);
    ASSERT_EQ(n, 2048u);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    const double t_scale = std::sqrt(2.0 * 9.81 / a);  // T = t * t_scale
    std::vector<double> T{0.0}, Z{1.0};
    std::vector<float> front;
    const double t_end = kMartinMoyce[std::size(kMartinMoyce) - 1].T / t_scale + 0.01;
    for (std::uint64_t f = 0; sim.time() < t_end; ++f) {
        sim.step_serial(ps, f);
        front.assign(ps.x().begin(), ps.x().end());
        std::nth_element(front.begin(), front.begin() + kFrontRank, front.end(), std::greater<float>());
        T.push_back(sim.time() * t_scale);
        Z.push_back(front[kFrontRank] / a);
    }
    ASSERT_TRUE(all_finite(ps));
    for (const FrontPoint& p : kMartinMoyce) {
        const auto it = std::lower_bound(T.begin(), T.end(), p.T);
        ASSERT_NE(it, T.end());
        const std::size_t k = static_cast<std::size_t>(it - T.begin());
        const double w = (p.T - T[k - 1]) / (T[k] - T[k - 1]);
        const double z = Z[k - 1] + w * (Z[k] - Z[k - 1]);
        const double err = (z - p.Z) / p.Z;
        std::printf("dam break T %.3f: Z/a simulated %.3f, Martin & Moyce %.3f, error %+.1f %%\n", p.T, z,
                    p.Z, 100.0 * err);
        EXPECT_LT(std::abs(err), 0.15) << "T " << p.T;
    }
}

// The container moved sideways pushes the fluid: after the tank jumps 5 cm in +x over one frame, the
// fluid's mean x velocity is positive and every particle is inside the moved tank.
TEST(SphSim, MovingTheContainerPushesTheFluid) {
    SphDesc desc = make_dambreak(1000);
    desc.fluid_boxes[0].max.x = desc.container.box.max.x;  // a pool filling the tank's floor
    desc.fluid_boxes[0].max.y = 0.1f;
    const std::size_t n = sph_seed_count(desc);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    for (std::uint64_t f = 0; f < 10; ++f) sim.step_serial(ps, f);
    sim.set_container_offset({0.05f, 0, 0});
    sim.step_serial(ps, 10);
    double vx = 0;
    for (float v : ps.vx()) vx += v;
    EXPECT_GT(vx / double(n), 0.2);
    const BoxCollider t = sim.tank();
    EXPECT_FLOAT_EQ(t.min.x, desc.container.box.min.x + 0.05f);
    for (std::size_t i = 0; i < n; ++i) {
        ASSERT_GE(ps.x()[i], t.min.x);
        ASSERT_LE(ps.x()[i], t.max.x);
    }
}

// A tank moved faster than max_substeps substeps a frame can follow (here by an input track's jump) is a
// clear error at that frame, not minutes of solves at their iteration limit; up to the limit it moves.
TEST(SphSim, ATankMovedFasterThanTheSubstepsCanFollowIsAnError) {
    const SphDesc desc = make_dambreak(1000);
    const std::size_t n = sph_seed_count(desc);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    const float most = static_cast<float>(sph_max_tank_speed(desc));
    EXPECT_NEAR(most, desc.step_cfl() * desc.spacing * float(desc.max_substeps) / desc.dt, 1e-3f * most);
    sim.set_container_offset({0.9f * most * desc.dt, 0, 0});
    sim.step_serial(ps, 0);
    sim.set_container_offset({0.9f * most * desc.dt + 1.2f * most * desc.dt, 0, 0});
    try {
        sim.step_serial(ps, 1);
        ADD_FAILURE() << "no error";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("the tank moves at"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("in frame 1"), std::string::npos) << e.what();
    }
}

// DFSPH picks each substep's length as it starts: from the fastest particle then, not the frame's start,
// so every substep holds the CFL condition (with its own gravity) and the frame still ends on time. In a
// dam break's surge the flow speeds up within a frame, so a frame's substeps differ.
TEST(SphSim, DfsphSubstepsHoldTheCflAtTheirStartAndEndTheFrameOnTime) {
    const SphDesc desc = make_dambreak(1500);
    const std::size_t n = sph_seed_count(desc);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    const double g = std::sqrt(double(dot(desc.gravity, desc.gravity)));
    double largest_spread = 1.0;
    for (std::uint64_t f = 0; f < 40; ++f) {
        sim.begin_frame(ps, f);
        double sum = 0, shortest = 1e9, longest = 0;
        int count = 0;
        for (std::size_t p = sim.next_phase(); p != SphSimulation::kPhaseCount; p = sim.next_phase()) {
            const double v = max_speed(ps);  // the last substep's velocities (the frame's start: the seed's)
            const std::size_t chunks = sim.phases()[p].parallel ? sim.chunks() : 1;
            for (std::size_t c = 0; c < chunks; ++c) sim.run_phase(p, c, ps);
            if (p != SphSimulation::kSubstep) continue;
            const double dt = sim.substep_dt();
            ++count;
            sum += dt;
            shortest = std::min(shortest, dt), longest = std::max(longest, dt);
            EXPECT_LE(dt * (v + g * dt), desc.step_cfl() * desc.spacing * (1.0 + 1e-5)) << "frame " << f;
        }
        sim.end_frame(ps);
        EXPECT_EQ(sim.substeps(), count);
        EXPECT_NEAR(sum, desc.dt, 1e-6 * desc.dt) << "frame " << f;
        largest_spread = std::max(largest_spread, longest / shortest);
    }
    EXPECT_GT(largest_spread, 1.02) << "the surge changes the step within a frame";
}

// A dam break's mechanical energy (kinetic plus potential, per particle) never grows: walls at rest do
// no work, and pressure and viscosity only trade and dissipate it. The 1 m column of the reference dam
// break hits the far wall at 6 m/s around frame 50; at CFL 0.2 (half the number then the default, twice
// the substeps a second) a solve warm-started from the last substep's stiffness pushed the stopped fluid out
// again at every substep, and the energy grew sixfold by frame 100. Coarse (a 12^3 lattice) to stay short. At
// that CFL number with plain Jacobi iterations, and at the solver's own (0.75, nearly four times the substep;
// from 0.85 on this coarse column ends frame 15 above its starting energy) with and without the
// Chebyshev acceleration, whose extrapolated stiffness must not overshoot into energy either. (At 0.2
// with Chebyshev one frame gains 1.1 %, 1.7 % over the run, never above the start; docs/sph.md.)
class DfsphEnergyTest : public ::testing::TestWithParam<std::tuple<float, float>> {};

TEST_P(DfsphEnergyTest, WallImpactAddsNoEnergy) {
    SphDesc desc = make_dambreak_reference(2000);
    desc.cfl = std::get<0>(GetParam());
    desc.chebyshev = std::get<1>(GetParam());
    const std::size_t n = sph_seed_count(desc);
    SphSimulation sim(desc, n);
    ParticleSet ps(n);
    sim.seed(ps);
    const auto energy = [&] {
        double e = 0;
        for (std::size_t i = 0; i < n; ++i) {
            const double v2 = double(ps.vx()[i]) * ps.vx()[i] + double(ps.vy()[i]) * ps.vy()[i] +
                              double(ps.vz()[i]) * ps.vz()[i];
            e += 0.5 * v2 - double(desc.gravity.y) * ps.y()[i];
        }
        return e / double(n);
    };
    const double start = energy();
    double last = start;
    for (std::uint64_t f = 0; f < 100; ++f) {
        sim.step_serial(ps, f);
        const double now = energy();
        ASSERT_LE(now, start) << "frame " << f;
        // Converting the density solve's leftover error into velocity may add a little.
        EXPECT_LE(now - last, 0.01 * start) << "frame " << f;
        last = now;
    }
    EXPECT_LT(last, 0.8 * start) << "the splash dissipates";
}

std::string energy_case_name(const ::testing::TestParamInfo<std::tuple<float, float>>& c) {
    const float cfl = std::get<0>(c.param), rho = std::get<1>(c.param);
    return std::string(cfl > 0 ? "Cfl02" : "SolversCfl") + (rho > 0 ? "Chebyshev" : "Jacobi");
}
INSTANTIATE_TEST_SUITE_P(SphSim, DfsphEnergyTest,
                         ::testing::Values(std::make_tuple(0.2f, 0.0f), std::make_tuple(0.0f, 0.8f),
                                           std::make_tuple(0.0f, 0.0f)),
                         energy_case_name);

// DFSPH takes 0.75 spacings a substep unless the scene sets a number, WCSPH 0.4 of h over the sound speed:
// the explicit solver's step must resolve its pressure waves, the implicit one's only the flow.
TEST(SphSim, EachSolverHasItsOwnCflNumberUnlessTheSceneSetsOne) {
    SphDesc desc = make_dambreak(500);
    EXPECT_EQ(desc.cfl, 0.0f);
    EXPECT_EQ(desc.step_cfl(), 0.75f);
    desc.solver = SphSolver::kWcsph;
    EXPECT_EQ(desc.step_cfl(), 0.4f);
    desc.cfl = 0.25f;
    EXPECT_EQ(desc.step_cfl(), 0.25f);
    desc.solver = SphSolver::kDfsph;
    EXPECT_EQ(desc.step_cfl(), 0.25f);
}

TEST(SphSim, BuiltInScenesRunAndStayFinite) {
    for (SphDesc desc : {make_dambreak(1500), make_drop(1500), make_slosh(1500)}) {
        const std::size_t n = sph_seed_count(desc);
        EXPECT_GT(n, 1000u) << desc.name;
        EXPECT_LT(n, 2200u) << desc.name;
        SphSimulation sim(desc, n);
        ParticleSet ps(n);
        sim.seed(ps);
        for (std::uint64_t f = 0; f < 20; ++f) sim.step_serial(ps, f);
        EXPECT_TRUE(all_finite(ps)) << desc.name;
        // Every particle stays within the scene's framing box.
        for (std::size_t i = 0; i < n; ++i) {
            ASSERT_GE(ps.y()[i], desc.bounds.min.y) << desc.name;
            ASSERT_LE(ps.x()[i], desc.bounds.max.x) << desc.name;
        }
    }
}

INSTANTIATE_TEST_SUITE_P(SphSim, SphSolverTest, ::testing::Values(SphSolver::kDfsph, SphSolver::kWcsph),
                         [](const auto& param) {
                             return std::string(param.param == SphSolver::kDfsph ? "Dfsph" : "Wcsph");
                         });

}  // namespace
}  // namespace rivulet
