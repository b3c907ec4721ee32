// SPH simulation speed over a whole dam break (systems/sim/sph_simulation.h): simulated 1/60 s frames per
// second of wall time, from the release through the surge, the splash against the far wall and after,
// at each particle count and thread count (each parallel phase over its chunks with tbb::parallel_for in
// a task_arena of that width). Per row: frames/s over the run and per third of it (release, surge,
// splash), substeps and solver iterations per frame, the largest density error a substep left, and the
// share of time in neighbour work (grid sort and lists), solver iterations and the rest, and the hash of
// the last frame's particles (positions, velocities, ids), which must be the same at every thread count.
//   bench_sph [--quick] [--frames N] [--sizes 8000,24000] [--threads 1,2] [--solver dfsph|wcsph]
//             [--cfl X] [--max-error PERCENT] [--chunks N] [--scene dambreak|reference]
// --chunks: pieces per parallel phase (0: the simulation's own choice, SphSimulation's constructor).
// --scene reference: SPlisHSPlasH's DamBreakModel geometry (make_dambreak_reference), on which the
// reference figures of docs/sph.md were measured; 24,389 particles there are its 29^3 lattice.
// --quick: 8k and 24k, 60 frames. Defaults: 8k, 24k, 64k, 256k; 180 frames (3 s); threads 1 and 2.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "jobs/mesh_hash.h"
#include "perf/support/bench_util.h"
#include "systems/particles/particle_hash.h"
#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"

namespace {

using Clock = std::chrono::steady_clock;
using rivulet::SphSimulation;

double seconds_since(Clock::time_point t0) {
    return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Where a phase's time goes: 0 neighbours (grid sort, lists or density), 1 solver (iterations or forces),
// 2 the rest (substep setup, predict, integrate).
int share_of(std::size_t phase) {
    switch (phase) {
        case SphSimulation::kGridCount:
        case SphSimulation::kGridCursors:
        case SphSimulation::kGridOffsets:
        case SphSimulation::kGridScatter:
        case SphSimulation::kWarmStart:
        case SphSimulation::kNeighbours:
        case SphSimulation::kDensity:
            return 0;
        case SphSimulation::kDivergence:
        case SphSimulation::kCorrect:
        case SphSimulation::kDensityError:
        case SphSimulation::kForces:
            return 1;
        default:
            return 2;
    }
}

struct Row {
    double seconds = 0;
    double third_fps[3] = {0, 0, 0};
    double substeps = 0, divergence = 0, density = 0, max_error = 0;
    double share[3] = {0, 0, 0};
    std::size_t particles = 0;
    std::uint64_t hash = 0;  // of the last frame's particles
};

Row run(const rivulet::SphDesc& desc, int threads, int frames, std::size_t chunks) {
    const std::size_t n = rivulet::sph_seed_count(desc);
    SphSimulation sim(desc, n, chunks);
    rivulet::ParticleSet ps(n);
    sim.seed(ps);
    tbb::task_arena arena(threads);
    Row r;
    r.particles = n;
    double third_seconds[3] = {0, 0, 0};
    int third_frames[3] = {0, 0, 0};
    arena.execute([&] {
        for (int f = 0; f < frames; ++f) {
            const auto t0 = Clock::now();
            sim.begin_frame(ps, std::uint64_t(f));
            for (std::size_t p = sim.next_phase(); p != SphSimulation::kPhaseCount; p = sim.next_phase()) {
                const auto tp = Clock::now();
                if (sim.phases()[p].parallel) {
                    tbb::parallel_for(
                        tbb::blocked_range<std::size_t>(0, sim.chunks(), 1),
                        [&](const tbb::blocked_range<std::size_t>& rg) {
                            for (std::size_t c = rg.begin(); c != rg.end(); ++c) sim.run_phase(p, c, ps);
                        },
                        tbb::simple_partitioner());
                } else {
                    sim.run_phase(p, 0, ps);
                }
                r.share[share_of(p)] += seconds_since(tp);
            }
            sim.end_frame(ps);
            const double s = seconds_since(t0);
            r.seconds += s;
            const int third = std::min(2, 3 * f / frames);
            third_seconds[third] += s, ++third_frames[third];
            r.substeps += sim.substeps();
            r.divergence += sim.divergence_iterations();
            r.density += sim.density_iterations();
            r.max_error = std::max(r.max_error, sim.density_error());
        }
    });
    for (int t = 0; t < 3; ++t)
        r.third_fps[t] = third_seconds[t] > 0 ? third_frames[t] / third_seconds[t] : 0;
    const double total = r.share[0] + r.share[1] + r.share[2];
    for (double& s : r.share) s = total > 0 ? 100.0 * s / total : 0;
    r.substeps /= frames, r.divergence /= frames, r.density /= frames;
    r.hash = rivulet::particle_hash(ps);
    return r;
}

}  // namespace

int main(int argc, char** argv) try {
    std::vector<long> sizes{8000, 24000, 64000, 256000}, threads{1, 2};
    int frames = 180;
    rivulet::SphSolver solver = rivulet::SphSolver::kDfsph;
    float cfl = 0, max_error = 0, chebyshev = -1;
    long chunks = 0;
    std::string scene = "dambreak";
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const bool more = i + 1 < argc;
        if (a == "--quick") {
            sizes = {8000, 24000}, frames = 60;
        } else if (a == "--frames" && more) {
            frames = std::max(3, std::atoi(argv[++i]));
        } else if (a == "--sizes" && more) {
            sizes = rivulet::bench::parse_list(argv[++i], "size");
        } else if (a == "--threads" && more) {
            threads = rivulet::bench::parse_list(argv[++i], "thread count");
        } else if (a == "--solver" && more) {
            solver =
                std::string(argv[++i]) == "wcsph" ? rivulet::SphSolver::kWcsph : rivulet::SphSolver::kDfsph;
        } else if (a == "--cfl" && more) {
            cfl = static_cast<float>(std::atof(argv[++i]));
        } else if (a == "--chebyshev" && more) {
            chebyshev = static_cast<float>(std::atof(argv[++i]));
        } else if (a == "--max-error" && more) {
            max_error = static_cast<float>(std::atof(argv[++i]));
        } else if (a == "--chunks" && more) {
            chunks = std::max(0L, std::atol(argv[++i]));
        } else if (a == "--scene" && more) {
            scene = argv[++i];
            if (scene != "dambreak" && scene != "reference") {
                std::fprintf(stderr, "bench_sph: --scene must be dambreak or reference\n");
                return 2;
            }
        } else {
            std::fprintf(
                stderr,
                "usage: bench_sph [--quick] [--frames N] [--sizes a,b] [--threads a,b] "
                "[--solver dfsph|wcsph] [--cfl X] [--chebyshev RHO] [--max-error PERCENT] [--chunks N] "
                "[--scene dambreak|reference]\n");
            return 2;
        }
    }
    std::printf("SPH dam break (%s), %s, %d frames of 1/60 s (%.1f s simulated), Release\n", scene.c_str(),
                solver == rivulet::SphSolver::kDfsph ? "DFSPH" : "WCSPH", frames, frames / 60.0);
    std::printf("%9s %7s %8s %8s %8s %8s %8s %8s %8s %9s %6s %6s %6s %16s\n", "particles", "threads",
                "frames/s", "release", "surge", "splash", "substeps", "div_it", "dens_it", "max_err%", "nbr%",
                "solve%", "rest%", "hash");
    for (long size : sizes) {
        const std::size_t count = std::size_t(std::max(size, 100L));
        rivulet::SphDesc desc =
            scene == "reference" ? rivulet::make_dambreak_reference(count) : rivulet::make_dambreak(count);
        desc.solver = solver;
        if (cfl > 0) desc.cfl = cfl;
        if (chebyshev >= 0) desc.chebyshev = chebyshev;
        if (max_error > 0) desc.max_density_error = max_error;
        for (long t : threads) {
            const Row r = run(desc, int(t), frames, std::size_t(chunks));
            std::printf("%9zu %7ld %8.2f %8.2f %8.2f %8.2f %8.1f %8.1f %8.1f %9.4f %6.1f %6.1f %6.1f %16s\n",
                        r.particles, t, frames / r.seconds, r.third_fps[0], r.third_fps[1], r.third_fps[2],
                        r.substeps, r.divergence, r.density, 100.0 * r.max_error, r.share[0], r.share[1],
                        r.share[2], rivulet::hash_hex(r.hash).c_str());
            std::fflush(stdout);
        }
    }
    return 0;
} catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_sph: %s\n", e.what());
    return 2;
}
