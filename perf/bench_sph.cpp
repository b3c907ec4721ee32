// SPH step time (systems/sim/sph_simulation.h) on the dambreak scene at 1k, 8k, 64k and 256k particles,
// at 1 and 2 threads: median ms per substep (all phases, each parallel phase over its chunks with
// tbb::parallel_for in a task_arena of the given width) and median ms per phase. A frame is
// substeps x this (the substep count is printed: CFL-limited at 60 frames/s).
//   bench_sph [--quick]      (--quick: 1k and 8k only)
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <vector>

#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"

namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Result {
    double step_ms = 0;
    std::vector<double> phase_ms;
    int substeps = 0;
    std::size_t chunks = 0;
};

Result run(std::size_t particles, int threads, int samples) {
    const rivulet::SphDesc desc = rivulet::make_dambreak(particles);
    const std::size_t n = rivulet::sph_seed_count(desc);
    rivulet::SphSimulation sim(desc, n);
    rivulet::ParticleSet ps(n);
    sim.seed(ps);
    tbb::task_arena arena(threads);
    Result r;
    r.chunks = sim.chunks();
    const std::size_t phases = sim.phases().size();
    std::vector<std::vector<double>> per_phase(phases);
    std::vector<double> steps;
    arena.execute([&] {
        r.substeps = sim.begin_frame(ps, 0);
        for (int s = 0; s < samples + 2; ++s) {  // two warm-up substeps (the first sort is the costly one)
            const auto t0 = Clock::now();
            for (std::size_t p = 0; p < phases; ++p) {
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
                if (s >= 2) per_phase[p].push_back(ms_since(tp));
            }
            if (s >= 2) steps.push_back(ms_since(t0));
            // Stay within the frame's substeps: start a new frame when they run out.
            if ((s + 1) % r.substeps == 0) {
                sim.end_frame(ps);
                sim.begin_frame(ps, 1);
            }
        }
    });
    r.step_ms = median(steps);
    for (auto& v : per_phase) r.phase_ms.push_back(median(v));
    return r;
}

}  // namespace

int main(int argc, char** argv) {
    const bool quick = argc > 1 && std::strcmp(argv[1], "--quick") == 0;
    std::vector<std::size_t> sizes{1000, 8000, 64000, 256000};
    if (quick) sizes.resize(2);
    std::printf("SPH dambreak, median ms per substep and per phase (Release)\n");
    std::printf("%9s %7s %7s %8s %10s", "particles", "threads", "chunks", "substeps", "substep_ms");
    const rivulet::SphSimulation names(rivulet::make_dambreak(100), 1);
    for (const rivulet::SphPhase& ph : names.phases()) std::printf(" %12s", ph.name + 4);  // without "sph."
    std::printf("\n");
    for (std::size_t n : sizes) {
        const int samples = n >= 200000 ? 5 : n >= 50000 ? 9 : 21;
        for (int threads : {1, 2}) {
            const Result r = run(n, threads, samples);
            std::printf("%9zu %7d %7zu %8d %10.3f", n, threads, r.chunks, r.substeps, r.step_ms);
            for (double ms : r.phase_ms) std::printf(" %12.3f", ms);
            std::printf("\n");
            std::fflush(stdout);
        }
    }
    return 0;
}
