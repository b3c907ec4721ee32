// Google Benchmark microbenchmarks of the marching-slices jobs and the SPH phases, one thread, each job
// over all its items. Inputs: a 24^3 lattice block (13,824 particles, r = 0.01, voxel r / 2) for slices;
// the dam break at 8,000 particles for SPH (after one frame, so the grid and densities are warm).
//   build/bin/bench_jobs_slices_sph --benchmark_min_time=0.2
// The SPH state can be a later one: RIVULET_BENCH_SPH_FRAMES=N simulates N frames first (the passes'
// cost changes over a dam break: 45 is mid-release, 120 after the splash), RIVULET_BENCH_SPH_PARTICLES
// sets the size.
#include <benchmark/benchmark.h>

#include <cstdlib>

#include "systems/particles/particle_set.h"
#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"
#include "systems/slices/slices_extractor.h"

namespace {

using namespace rivulet;

struct SlicesFixture {
    static constexpr int kSide = 24;
    static constexpr float kRadius = 0.01f;
    ParticleSet set{std::size_t(kSide) * kSide * kSide};
    SlicesSettings settings;
    std::unique_ptr<SlicesExtractor> slices;
    SurfaceMesh mesh;

    SlicesFixture() {
        std::uint32_t id = 0;
        for (int k = 0; k < kSide; ++k)
            for (int j = 0; j < kSide; ++j)
                for (int i = 0; i < kSide; ++i)
                    set.push(2 * kRadius * float(i), 2 * kRadius * float(j), 2 * kRadius * float(k), 0, 0, 0,
                             id++);
        settings.radius = kRadius;
        slices = std::make_unique<SlicesExtractor>(settings, set.size());
        slices->reserve_scratch(1);
        slices->extract_serial(set.positions(), mesh);
    }
    static SlicesFixture& get() {
        static SlicesFixture f;
        return f;
    }
    void counters(benchmark::State& state) const {
        state.counters["blocks"] = slices->blocks();
        state.counters["triangles"] = static_cast<double>(mesh.triangle_count());
    }
};

void BM_SlicesBlockBins(benchmark::State& state) {
    auto& f = SlicesFixture::get();
    const auto p = f.set.positions();
    for (auto _ : state) {
        f.slices->begin_frame(p);
        for (std::uint32_t c = 0; c < f.slices->chunks(); ++c) f.slices->block_count(p, c);
        f.slices->block_prefix();
        for (std::uint32_t c = 0; c < f.slices->chunks(); ++c) f.slices->block_scatter(p, c);
        benchmark::ClobberMemory();
    }
    f.slices->extract_serial(p, f.mesh);  // leave a whole frame behind for the other benchmarks
    f.counters(state);
}
BENCHMARK(BM_SlicesBlockBins)->Unit(benchmark::kMicrosecond);

void BM_SlicesBlocks(benchmark::State& state) {
    auto& f = SlicesFixture::get();
    for (auto _ : state) {
        for (std::uint32_t b = 0; b < f.slices->blocks(); ++b) f.slices->extract_block(b);
        benchmark::ClobberMemory();
    }
    f.slices->extract_serial(f.set.positions(), f.mesh);
    f.counters(state);
}
BENCHMARK(BM_SlicesBlocks)->Unit(benchmark::kMillisecond);

void BM_SlicesWeld(benchmark::State& state) {
    auto& f = SlicesFixture::get();
    for (auto _ : state) {
        f.slices->weld_offsets(f.mesh);
        for (std::uint32_t b = 0; b < f.slices->blocks(); ++b) f.slices->weld_block(b, f.mesh);
        benchmark::ClobberMemory();
    }
    f.slices->extract_serial(f.set.positions(), f.mesh);
    f.counters(state);
}
BENCHMARK(BM_SlicesWeld)->Unit(benchmark::kMicrosecond);

void BM_SlicesNormalsAndStage(benchmark::State& state) {
    auto& f = SlicesFixture::get();
    for (auto _ : state) {
        for (std::uint32_t b = 0; b < f.slices->blocks(); ++b) f.slices->normals_block(b);
        f.slices->borders();
        for (std::uint32_t b = 0; b < f.slices->blocks(); ++b) f.slices->stage(b, f.mesh);
        benchmark::ClobberMemory();
    }
    f.slices->extract_serial(f.set.positions(), f.mesh);
    f.counters(state);
}
BENCHMARK(BM_SlicesNormalsAndStage)->Unit(benchmark::kMicrosecond);

std::size_t env_count(const char* name, std::size_t fallback) {
    const char* text = std::getenv(name);
    return text != nullptr && std::atol(text) > 0 ? static_cast<std::size_t>(std::atol(text)) : fallback;
}

struct SphFixture {
    SphDesc desc = make_dambreak(env_count("RIVULET_BENCH_SPH_PARTICLES", 8000));
    ParticleSet set;
    std::unique_ptr<SphSimulation> sim;

    explicit SphFixture(SphSolver solver) {
        desc.solver = solver;
        set.reserve(sph_seed_count(desc));
        sim = std::make_unique<SphSimulation>(desc, sph_seed_count(desc));
        sim->seed(set);
        const std::size_t frames = env_count("RIVULET_BENCH_SPH_FRAMES", 1);
        for (std::size_t f = 0; f < frames; ++f) sim->step_parallel(set, f);
        sim->begin_frame(set, frames);
        if (solver == SphSolver::kDfsph) run(SphSimulation::kSubstep, SphSimulation::kNeighbours);
    }
    static SphFixture& get(SphSolver solver = SphSolver::kWcsph) {
        if (solver == SphSolver::kWcsph) {
            static SphFixture wcsph(SphSolver::kWcsph);
            return wcsph;
        }
        static SphFixture dfsph(SphSolver::kDfsph);  // made only when a DFSPH benchmark runs
        return dfsph;
    }
    // Runs phases [first, last] over all their chunks, serially.
    void run(std::size_t first, std::size_t last) {
        for (std::size_t p = first; p <= last; ++p) {
            const std::size_t n = sim->phases()[p].parallel ? sim->chunks() : 1;
            for (std::size_t c = 0; c < n; ++c) sim->run_phase(p, c, set);
        }
    }
};

void sph_phases(benchmark::State& state, std::size_t first, std::size_t last,
                SphSolver solver = SphSolver::kWcsph) {
    auto& f = SphFixture::get(solver);
    for (auto _ : state) {
        f.run(first, last);
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * f.set.size()));
    state.counters["particles"] = static_cast<double>(f.set.size());
}

void BM_SphGrid(benchmark::State& state) {
    sph_phases(state, SphSimulation::kSubstep, SphSimulation::kGridScatter);
}
BENCHMARK(BM_SphGrid)->Unit(benchmark::kMicrosecond);

void BM_SphDensity(benchmark::State& state) {
    sph_phases(state, SphSimulation::kDensity, SphSimulation::kDensity);
}
BENCHMARK(BM_SphDensity)->Unit(benchmark::kMicrosecond);

void BM_SphForces(benchmark::State& state) {
    sph_phases(state, SphSimulation::kForces, SphSimulation::kForces);
}
BENCHMARK(BM_SphForces)->Unit(benchmark::kMicrosecond);

void BM_SphIntegrate(benchmark::State& state) {
    sph_phases(state, SphSimulation::kIntegrate, SphSimulation::kIntegrate);
}
BENCHMARK(BM_SphIntegrate)->Unit(benchmark::kMicrosecond);

// DFSPH: the lists (once per substep), a residual and a correction (once each per solver iteration).
void BM_DfsphNeighbours(benchmark::State& state) {
    sph_phases(state, SphSimulation::kNeighbours, SphSimulation::kNeighbours, SphSolver::kDfsph);
}
BENCHMARK(BM_DfsphNeighbours)->Unit(benchmark::kMicrosecond);

void BM_DfsphResidual(benchmark::State& state) {
    sph_phases(state, SphSimulation::kDensityError, SphSimulation::kDensityError, SphSolver::kDfsph);
}
BENCHMARK(BM_DfsphResidual)->Unit(benchmark::kMicrosecond);

void BM_DfsphCorrect(benchmark::State& state) {
    sph_phases(state, SphSimulation::kCorrect, SphSimulation::kCorrect, SphSolver::kDfsph);
}
BENCHMARK(BM_DfsphCorrect)->Unit(benchmark::kMicrosecond);

// The rest of a substep: the prediction (gravity, viscosity, the density solve's warm start and the
// divergence solve's first look, once) and the cell sort (the phases from the substep's start to the
// scatter).
void BM_DfsphPredict(benchmark::State& state) {
    sph_phases(state, SphSimulation::kPredict, SphSimulation::kPredict, SphSolver::kDfsph);
}
BENCHMARK(BM_DfsphPredict)->Unit(benchmark::kMicrosecond);

void BM_DfsphGrid(benchmark::State& state) {
    sph_phases(state, SphSimulation::kSubstep, SphSimulation::kGridScatter, SphSolver::kDfsph);
}
BENCHMARK(BM_DfsphGrid)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
