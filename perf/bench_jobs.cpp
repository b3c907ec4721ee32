// Microbenchmarks of the per-frame jobs, each run serially on the calling thread (no TBB):
//   BM_BinSort          begin_frame + bin_count (all chunks) + bin_prefix + bin_scatter (all chunks)
//   BM_Grouping         all grouping jobs: bin_neighbours (every bin) + group (rules) + spread, list_offsets
//                       and lists (every bin chunk); BM_GroupingNeighbours / BM_GroupingRules /
//                       BM_GroupingLists time each phase alone
//   BM_DeformAll        ScanConverter::deform of every cylinder piece
//   BM_NormalsAll       ScanConverter::normals of every cylinder piece
//   BM_CircleMaximaSmooth / BM_GaussianBlend   one ring (U = 20) of 10 circles (jobs/cross_section.h)
//   BM_FountainFrame    StreamSimulation::step_serial, one frame of the fountain scene in steady state
// The scan jobs use the 8,000-particle falling stream of bench_scan_table.cpp (same generator, copied
// below), U = 20, V = 120, radius 0.02.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "jobs/counter_rng.h"
#include "jobs/cross_section.h"
#include "perf/support/falling_stream.h"
#include "systems/particles/particle_set.h"
#include "systems/scan/scan_converter.h"
#include "systems/scenes/scene.h"
#include "systems/sim/stream_sim.h"

namespace {

constexpr float kRadius = rivulet::perf::kStreamRadius;
constexpr std::uint64_t kSeed = 2008;
constexpr std::size_t kParticles = 8000;

using rivulet::perf::falling_stream;

// The 8,000-particle stream, binned and grouped once (so each benchmark can run its job alone).
struct ScanFixture {
    rivulet::ParticleSet set = falling_stream(kParticles);
    rivulet::ScanConverter scan{settings(set), kParticles};
    rivulet::ScanOutput out;

    static rivulet::ScanSettings settings(const rivulet::ParticleSet& s) {
        const auto y = s.y();
        const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
        rivulet::ScanSettings st;
        st.radius = kRadius;
        st.v_top = *hi + 0.5f * kRadius;
        st.v_bottom = *lo - 0.5f * kRadius;
        return st;
    }
    ScanFixture() {
        scan.prepare_output(out);
        scan.extract_serial(set.positions(), out);
    }
    // Every grouping job of a frame, in order (as the frame graph runs them).
    void group_all() {
        for (std::uint32_t b = 0; b < scan.bins_count(); ++b) scan.bin_neighbours(b);
        scan.group();
        group_lists();
    }
    void group_lists() {
        for (std::uint32_t c = 0; c < scan.bin_chunks(); ++c) scan.spread(c);
        scan.list_offsets();
        for (std::uint32_t c = 0; c < scan.bin_chunks(); ++c) scan.lists(c);
    }
    static ScanFixture& get() {
        static ScanFixture f;
        return f;
    }
};

void counters(benchmark::State& state, const ScanFixture& f) {
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * f.set.size()));
    state.counters["groups"] = f.scan.groups();
    state.counters["isolated"] = f.out.sphere_count;
}

void BM_BinSort(benchmark::State& state) {
    auto& f = ScanFixture::get();
    const auto p = f.set.positions();
    for (auto _ : state) {
        f.scan.begin_frame(p);
        for (std::uint32_t c = 0; c < f.scan.chunks(); ++c) f.scan.bin_count(p, c);
        f.scan.bin_prefix();
        for (std::uint32_t c = 0; c < f.scan.chunks(); ++c) f.scan.bin_scatter(p, c);
        benchmark::ClobberMemory();
    }
    f.group_all();  // begin_frame cleared the grouping the other benchmarks rely on
    counters(state, f);
    state.counters["bin_entries"] = static_cast<double>(f.scan.bins().entries.size());
}
BENCHMARK(BM_BinSort)->Unit(benchmark::kMicrosecond);

void BM_Grouping(benchmark::State& state) {
    auto& f = ScanFixture::get();
    for (auto _ : state) {
        f.group_all();
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_Grouping)->Unit(benchmark::kMicrosecond);

// The grouping phases alone: per-bin neighbour search (lazy hashes and events included), the serial
// rules over the events, and spreading groups + building the group lists.
void BM_GroupingNeighbours(benchmark::State& state) {
    auto& f = ScanFixture::get();
    for (auto _ : state) {
        for (std::uint32_t b = 0; b < f.scan.bins_count(); ++b) f.scan.bin_neighbours(b);
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_GroupingNeighbours)->Unit(benchmark::kMicrosecond);

void BM_GroupingRules(benchmark::State& state) {
    auto& f = ScanFixture::get();
    for (auto _ : state) {
        f.scan.group();
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_GroupingRules)->Unit(benchmark::kMicrosecond);

void BM_GroupingLists(benchmark::State& state) {
    auto& f = ScanFixture::get();
    for (auto _ : state) {
        f.group_lists();
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_GroupingLists)->Unit(benchmark::kMicrosecond);

void BM_DeformAll(benchmark::State& state) {
    auto& f = ScanFixture::get();
    const auto p = f.set.positions();
    for (auto _ : state) {
        for (std::uint32_t i = 0; i < f.scan.pieces(); ++i) f.scan.deform(p, i, f.out);
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_DeformAll)->Unit(benchmark::kMicrosecond);

void BM_NormalsAll(benchmark::State& state) {
    auto& f = ScanFixture::get();
    for (auto _ : state) {
        for (std::uint32_t i = 0; i < f.scan.pieces(); ++i) f.scan.normals(i, f.out);
        benchmark::ClobberMemory();
    }
    counters(state, f);
}
BENCHMARK(BM_NormalsAll)->Unit(benchmark::kMicrosecond);

// One cross-section: 10 circles on a ring (a stream's slice), relative to their centroid; U = 20.
struct Ring {
    static constexpr std::uint32_t kU = 20;
    static constexpr std::size_t kCircles = 10;
    std::vector<float> cx, cz, rho, cos_t, sin_t, r, tmp;
    Ring() : r(kU), tmp(kU) {
        for (std::size_t i = 0; i < kCircles; ++i) {
            const float a = 2.0f * std::numbers::pi_v<float> * static_cast<float>(i) / kCircles;
            const float d = 0.03f + 0.004f * rivulet::counter_uniform(kSeed, 2, i, 0);
            cx.push_back(d * std::cos(a));
            cz.push_back(d * std::sin(a));
            rho.push_back(0.012f +
                          0.008f * rivulet::counter_uniform(kSeed, 2, i, 1));  // a sphere cut off-centre
        }
        for (std::uint32_t k = 0; k < kU; ++k) {
            const double t = 2.0 * std::numbers::pi * k / kU;
            cos_t.push_back(static_cast<float>(std::cos(t)));
            sin_t.push_back(static_cast<float>(std::sin(t)));
        }
    }
    rivulet::CirclesView circles() const { return {cx, cz, rho}; }
    rivulet::AngleTable angles() const { return {cos_t, sin_t}; }
};

void BM_CircleMaximaSmooth(benchmark::State& state) {
    Ring ring;
    for (auto _ : state) {
        rivulet::circle_maxima(ring.circles(), ring.angles(), ring.r);
        rivulet::smooth_cyclic(ring.r, 10, ring.tmp);
        benchmark::DoNotOptimize(ring.r.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_CircleMaximaSmooth)->Unit(benchmark::kNanosecond);

void BM_GaussianBlend(benchmark::State& state) {
    Ring ring;
    for (auto _ : state) {
        rivulet::gaussian_blend(ring.circles(), ring.angles(), 1.0f, ring.r, ring.tmp);
        benchmark::DoNotOptimize(ring.r.data());
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_GaussianBlend)->Unit(benchmark::kNanosecond);

void BM_FountainFrame(benchmark::State& state) {
    const rivulet::SceneDesc scene = rivulet::make_builtin_scene("fountain");
    rivulet::StreamSimulation sim(scene);
    rivulet::ParticleSet particles(scene.max_particles);
    std::uint64_t frame = 0;
    for (; frame < static_cast<std::uint64_t>(scene.warmup_frames); ++frame)
        sim.step_serial(particles, frame);
    std::size_t processed = 0;
    for (auto _ : state) {
        sim.step_serial(particles, frame++);
        processed += particles.size();
        benchmark::ClobberMemory();
    }
    state.SetItemsProcessed(static_cast<std::int64_t>(processed));
    state.counters["particles"] = static_cast<double>(particles.size());
}
BENCHMARK(BM_FountainFrame)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
