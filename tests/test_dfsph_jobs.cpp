// The jobs of divergence-free SPH (jobs/dfsph_lists.h, jobs/dfsph_solve.h) on hand-made lattices: the
// wall's share completes a lattice's first layer to rest density and its slope is its derivative; inside
// a lattice the density ratio is 1 with 26 neighbours; the density solve brings a compressed block to the
// set error, conserving momentum exactly as the pairwise corrections promise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <vector>

#include "jobs/cpu_dispatch.h"
#include "jobs/dfsph_lists.h"
#include "jobs/dfsph_solve.h"

namespace rivulet {
namespace {

// A k^3 block of lattice points of spacing `s`, all in one grid cell (the cell search then visits every
// point: brute force).
struct Block {
    std::vector<float> x, y, z;
    std::vector<std::uint32_t> key, cell_start;
    SphGrid grid;
    Block(int k, float s) {
        for (int c = 0; c < k; ++c)
            for (int b = 0; b < k; ++b)
                for (int a = 0; a < k; ++a) {
                    x.push_back(float(a) * s), y.push_back(float(b) * s), z.push_back(float(c) * s);
                }
        key.assign(x.size(), 0);
        cell_start = {0, static_cast<std::uint32_t>(x.size())};
        grid.cell = 1000.0f;
    }
    SphNeighbourhood view() const { return {grid, cell_start, key, x, y, z}; }
    std::size_t size() const { return x.size(); }
};

struct Lists {
    DfsphChunkLists lists;
    std::vector<std::uint32_t> begin, end;
    std::vector<float> ratio, factor, gx, gy, gz, support, x4;
    explicit Lists(std::size_t n)
        : begin(n), end(n), ratio(n), factor(n), gx(n), gy(n), gz(n), support(n), x4(4 * n) {}
    DfsphParticleOut out() { return {begin, end, ratio, factor, gx, gy, gz, support, x4}; }
};

TEST(DfsphJobs, WallShareCompletesALatticeLayerAndItsSlopeIsItsDerivative) {
    const float d = 0.01f;
    const SphCubicKernel kernel(2.0f * d);
    const float volume = dfsph_lattice_volume(kernel, d);
    const DfsphWallTable table(kernel, volume, d);
    // The fluid's share at a point d/2 above the wall: the lattice rows on its side.
    double fluid = 0;
    for (int z = -3; z <= 3; ++z)
        for (int y = 0; y <= 3; ++y)
            for (int x = -3; x <= 3; ++x) fluid += kernel.w(float(x * x + y * y + z * z) * d * d);
    float b = 0, a = 0;
    table.at(0.5f * d, b, a);
    EXPECT_NEAR(volume * fluid + b, 1.0, 1e-4);
    float previous = 2.0f;
    for (int k = 0; k <= 40; ++k) {
        const float s = 0.05f * d * float(k);
        float bs = 0, as = 0;
        table.at(s, bs, as);
        EXPECT_LE(bs, previous) << "B falls with distance";
        previous = bs;
    }
    // Mid-sample, the slope A is the interpolated B's derivative (the solver's prediction is then exact to
    // first order).
    const float sample = table.h / DfsphWallTable::kSamples;
    for (int k = 0; k < DfsphWallTable::kSamples; k += 16) {
        const float s = (float(k) + 0.5f) * sample, e = 0.25f * sample;
        float b1 = 0, b2 = 0, as = 0, unused = 0;
        table.at(s, unused, as);
        table.at(s - e, b1, unused);
        table.at(s + e, b2, unused);
        EXPECT_NEAR(as, (b1 - b2) / (2 * e), 1e-3f * (as + 1.0f / d)) << "s " << s;
    }
    table.at(2.0f * d, b, a);
    EXPECT_EQ(b, 0.0f);
    EXPECT_EQ(a, 0.0f);
}

TEST(DfsphJobs, InsideALatticeTheDensityIsRestWithTwentySixNeighbours) {
    const float d = 0.01f;
    const Block block(7, d);
    const SphCubicKernel kernel(2.0f * d);
    const float volume = dfsph_lattice_volume(kernel, d);
    ASSERT_EQ(dfsph_lattice_neighbours(kernel, d), 26);
    Lists l(block.size());
    const DfsphWallTable table(kernel, volume, d);
    dfsph_build_lists(block.view(), kernel, volume, SphWalls{}, table, 26.0f, 0, block.size(), l.lists,
                      l.out());
    const std::size_t centre = (3 * 7 + 3) * 7 + 3;
    EXPECT_NEAR(l.ratio[centre], 1.0f, 1e-5f);
    // 26 lattice neighbours within 2 spacings, plus up to the 6 at exactly 2 spacings that rounding can
    // place a hair inside (with a gradient of almost 0).
    EXPECT_GE(l.end[centre] - l.begin[centre], 26u);
    EXPECT_LE(l.end[centre] - l.begin[centre], 32u);
    EXPECT_GT(l.factor[centre], 0.0f);
    // A corner point has 7 of its 26 neighbours and well under rest density.
    EXPECT_GE(l.end[0] - l.begin[0], 7u);
    EXPECT_LE(l.end[0] - l.begin[0], 10u);
    EXPECT_LT(l.ratio[0], 0.7f);
}

// Iterations of the density solve on a squeezed block until its average error is under 0.1 %, with
// Chebyshev weights from spectral radius estimate rho (0: plain relaxed Jacobi); velocities out.
struct BlockSolve {
    int iterations = 0;
    double first = 0, error = 0;
    std::vector<float> vx, vy, vz;
};

BlockSolve solve_squeezed_block(float rho, float dt) {
    const float d = 0.01f;
    const Block block(8, 0.92f * d);  // squeezed: about 28 % over rest density inside
    const SphCubicKernel kernel(2.0f * d);
    const float volume = dfsph_lattice_volume(kernel, d);
    const std::size_t n = block.size();
    Lists l(n);
    const DfsphWallTable table(kernel, volume, d);
    dfsph_build_lists(block.view(), kernel, volume, SphWalls{}, table, 26.0f, 0, n, l.lists, l.out());
    const DfsphContext c{block.x, block.y, block.z, l.x4,      {&l.lists, 1}, l.begin, l.end,
                         l.gx,    l.gy,    l.gz,    l.support, {0, 0, 0},     20.0f};
    BlockSolve s;
    s.vx.assign(n, 0.0f), s.vy.assign(n, 0.0f), s.vz.assign(n, 0.0f);
    std::vector<float> v4(4 * n, 0.0f), k(n, 0.0f), total(n, 0.0f);
    float weight = 1.0f;
    for (; s.iterations < 200; ++s.iterations) {
        weight = dfsph_chebyshev_weight(rho, s.iterations, weight);
        s.error = dfsph_residual(c, 0, 0, n, dt, v4, l.ratio, l.factor, total, k, 1.0f, weight) / double(n);
        if (s.iterations == 0) s.first = s.error;
        if (s.error < 0.001) break;
        dfsph_correct(c, 0, 0, n, k, {s.vx, s.vy, s.vz, v4});
        for (std::size_t i = 0; i < n; ++i) total[i] += k[i];
    }
    return s;
}

// The summed velocities against the summed speeds along x (each correction is pairwise symmetric, so
// momentum stays zero).
void expect_no_momentum(const BlockSolve& s) {
    double px = 0, py = 0, pz = 0, speed = 0;
    for (std::size_t i = 0; i < s.vx.size(); ++i)
        px += s.vx[i], py += s.vy[i], pz += s.vz[i], speed += std::abs(s.vx[i]);
    EXPECT_NEAR(px, 0.0, 1e-5 * speed);
    EXPECT_NEAR(py, 0.0, 1e-5 * speed);
    EXPECT_NEAR(pz, 0.0, 1e-5 * speed);
}

TEST(DfsphJobs, DensitySolveDecompressesABlockAndConservesMomentum) {
    const BlockSolve s = solve_squeezed_block(0.0f, 0.004f);
    EXPECT_GT(s.first, 0.05);
    EXPECT_LT(s.error, 0.001) << "after " << s.iterations << " iterations";
    expect_no_momentum(s);
    // The block expands: the corner point moves away from the centre.
    EXPECT_LT(s.vx[0], 0.0f);
    EXPECT_LT(s.vy[0], 0.0f);
    EXPECT_LT(s.vz[0], 0.0f);
}

// Chebyshev's weights (Golub & Varga; Wang 2015) on the same solve: the same bound in fewer iterations,
// the same momentum (every weight scales a symmetric pairwise correction).
TEST(DfsphJobs, ChebyshevWeightsReachTheBoundInFewerIterations) {
    EXPECT_EQ(dfsph_chebyshev_weight(0.9f, 0, 1.0f), 1.0f);
    EXPECT_EQ(dfsph_chebyshev_weight(0.0f, 3, 1.2f), 1.0f);
    EXPECT_EQ(dfsph_chebyshev_weight(0.9f, kDfsphChebyshevIterations + 1, 1.2f), 1.0f);
    EXPECT_FLOAT_EQ(dfsph_chebyshev_weight(0.9f, 1, 1.0f), 2.0f / (2.0f - 0.81f));
    EXPECT_FLOAT_EQ(dfsph_chebyshev_weight(0.9f, 2, 1.68f), 4.0f / (4.0f - 0.81f * 1.68f));
    for (const float dt : {0.002f, 0.004f}) {
        const BlockSolve jacobi = solve_squeezed_block(0.0f, dt), chebyshev = solve_squeezed_block(0.9f, dt);
        EXPECT_LT(jacobi.error, 0.001);
        EXPECT_LT(chebyshev.error, 0.001) << "after " << chebyshev.iterations << " iterations";
        EXPECT_EQ(chebyshev.first, jacobi.first);
        EXPECT_LE(chebyshev.iterations, jacobi.iterations * 2 / 3)
            << "Jacobi " << jacobi.iterations << ", Chebyshev " << chebyshev.iterations;
        expect_no_momentum(chebyshev);
    }
}

// A jittered lattice in a walled box, sorted into cells of h: its spacing does not divide h, so rows have
// every length and the AVX2 gather's full and masked loads both run. `jitter`: the offsets' span, in d.
struct SortedCloud {
    std::vector<float> x, y, z;
    std::vector<std::uint32_t> key, cell_start;
    SphGrid grid;
    SortedCloud(int k, float d, float h, float jitter_span = 0.6f) {
        std::vector<float> px, py, pz;
        std::uint32_t state = 12345u;
        const auto jitter = [&] {
            state = state * 1664525u + 1013904223u;
            return (float(state >> 8) / 16777216.0f - 0.5f) * jitter_span * d;
        };
        for (int c = 0; c < k; ++c)
            for (int b = 0; b < k; ++b)
                for (int a = 0; a < k; ++a) {
                    px.push_back(d * (float(a) + 0.5f) + jitter());
                    py.push_back(d * (float(b) + 0.5f) + jitter());
                    pz.push_back(d * (float(c) + 0.5f) + jitter());
                }
        grid.cell = h;
        grid.origin = {-h, -h, -h};
        grid.nx = grid.ny = grid.nz = static_cast<std::uint32_t>(std::ceil(float(k) * d / h)) + 2;
        std::vector<std::uint32_t> order(px.size()), keys(px.size());
        for (std::size_t i = 0; i < px.size(); ++i) keys[i] = grid.key(px[i], py[i], pz[i]);
        std::iota(order.begin(), order.end(), 0u);
        std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return keys[a] < keys[b]; });
        for (std::uint32_t i : order)
            x.push_back(px[i]), y.push_back(py[i]), z.push_back(pz[i]), key.push_back(keys[i]);
        cell_start.assign(grid.cells() + 1, 0);
        for (std::uint32_t kk : key) ++cell_start[kk + 1];
        for (std::size_t c = 0; c < grid.cells(); ++c) cell_start[c + 1] += cell_start[c];
    }
    SphNeighbourhood view() const { return {grid, cell_start, key, x, y, z}; }
    std::size_t size() const { return x.size(); }
};

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// The jittered cloud in a tank that just holds it, with the kernel and wall table of spacing d.
struct WalledCloud {
    static constexpr float d = 0.01f, h = 2.0f * d;
    SortedCloud cloud;
    SphCubicKernel kernel{h};
    float volume = dfsph_lattice_volume(kernel, d);
    DfsphWallTable table{kernel, volume, d};
    SphWalls walls;
    // `spacing` below d packs more neighbours within h (0.4 d: about 300, several batches a particle).
    explicit WalledCloud(int k, float spacing = 0.93f * d, float jitter_span = 0.6f)
        : cloud(k, spacing, h, jitter_span) {
        walls.enabled = true;
        for (int a = 0; a < 3; ++a) walls.min[a] = 0.0f, walls.max[a] = float(k) * spacing;
    }
    void build(Lists& l, const DfsphParticleOut& out, std::size_t b, std::size_t e, bool baseline) const {
        if (baseline)
            dfsph_build_lists_baseline(cloud.view(), kernel, volume, walls, table, 26.0f, b, e, l.lists, out);
        else
            dfsph_build_lists(cloud.view(), kernel, volume, walls, table, 26.0f, b, e, l.lists, out);
    }
};

// Each list starts at a multiple of four pairs and is padded to the next with (0, i), which the passes
// read as whole groups of four.
void expect_padded(const Lists& l, std::size_t i) {
    EXPECT_EQ(l.begin[i] % 4, 0u) << "particle " << i;
    for (std::uint32_t p = l.end[i]; p % 4 != 0; ++p) {
        EXPECT_EQ(l.lists.pairs[p].f, 0.0f) << "particle " << i;
        EXPECT_EQ(l.lists.pairs[p].j, i) << "particle " << i;
    }
}

// The build the CPU runs against the baseline: the same lists, values and bytes, each list padded (checked
// per chunk: the second writes its lists from the vector's start, over the first's).
void expect_builds_agree(const WalledCloud& w) {
    const std::size_t n = w.cloud.size();
    Lists fast(n), baseline(n);
    for (auto [b, e] : {std::pair<std::size_t, std::size_t>{0, n / 3}, {n / 3, n}}) {
        w.build(fast, fast.out(), b, e, false);
        w.build(baseline, baseline.out(), b, e, true);
        for (std::size_t i = b; i < e; ++i) expect_padded(fast, i), expect_padded(baseline, i);
    }
    for (std::size_t i = 0; i < n; ++i) {
        const std::size_t pairs = baseline.end[i] - baseline.begin[i];
        ASSERT_EQ(pairs, fast.end[i] - fast.begin[i]) << "particle " << i;
        ASSERT_EQ(0, std::memcmp(&fast.lists.pairs[fast.begin[i]], &baseline.lists.pairs[baseline.begin[i]],
                                 pairs * sizeof(DfsphPair)))
            << "particle " << i;
    }
    EXPECT_TRUE(same_bytes(fast.ratio, baseline.ratio));
    EXPECT_TRUE(same_bytes(fast.factor, baseline.factor));
    EXPECT_TRUE(same_bytes(fast.gx, baseline.gx) && same_bytes(fast.gy, baseline.gy) &&
                same_bytes(fast.gz, baseline.gz));
    EXPECT_TRUE(same_bytes(fast.support, baseline.support));
    EXPECT_TRUE(same_bytes(fast.x4, baseline.x4));
}

// Against brute force: exactly the others within h, in the cell search's order of cells.
void expect_lists_within_h(const WalledCloud& w) {
    const SortedCloud& cloud = w.cloud;
    const std::size_t n = cloud.size();
    Lists fast(n);
    // Two chunks, the second reusing nothing of the first.
    for (auto [b, e] : {std::pair<std::size_t, std::size_t>{0, n / 3}, {n / 3, n}}) {
        w.build(fast, fast.out(), b, e, false);
        for (std::size_t i = b; i < e; ++i) {
            // Against brute force: exactly the others within h, in the cell search's order of cells.
            std::vector<std::uint32_t> want, got;
            for (std::uint32_t j = 0; j < n; ++j) {
                const float dx = cloud.x[i] - cloud.x[j], dy = cloud.y[i] - cloud.y[j],
                            dz = cloud.z[i] - cloud.z[j];
                if (j != i && dx * dx + dy * dy + dz * dz < w.kernel.h2) want.push_back(j);
            }
            for (std::uint32_t p = fast.begin[i]; p < fast.end[i]; ++p) got.push_back(fast.lists.pairs[p].j);
            std::sort(got.begin(), got.end());
            ASSERT_EQ(got, want) << "particle " << i;
        }
    }
    expect_builds_agree(w);
}

TEST(DfsphJobs, ListsHoldTheNeighboursWithinHAndBothBuildsGiveTheSameBytes) {
    expect_lists_within_h(WalledCloud(12));
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 here: both runs were the baseline build";
}

// Offsets of up to 1.5 spacings scramble the lattice into clumps and gaps: cells hold from none to about
// twenty particles and their particles' boxes (which cull each cell's candidates) every size, so
// neighbours sit just inside h of a box's corners, edges and faces.
TEST(DfsphJobs, ListsHoldTheNeighboursWithinHWhereParticlesClumpAndCellsAreUneven) {
    for (const float span : {1.5f, 3.0f})
        expect_lists_within_h(WalledCloud(12, 0.93f * WalledCloud::d, span));
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 here: both runs were the baseline build";
}

TEST(DfsphJobs, BothBuildsGiveTheSameBytesWhereAParticleFillsSeveralBatches) {
    const WalledCloud dense(9, 0.4f * WalledCloud::d);
    std::size_t most = 0;  // neighbours of the densest particle: a batch holds 64 candidates
    {
        Lists l(dense.cloud.size());
        dense.build(l, l.out(), 0, dense.cloud.size(), true);
        for (std::size_t i = 0; i < dense.cloud.size(); ++i)
            most = std::max<std::size_t>(most, l.end[i] - l.begin[i]);
    }
    EXPECT_GT(most, 200u);
    expect_builds_agree(dense);
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 here: both runs were the baseline build";
}

// The divergence solve's warm start folded into the build: each velocity changes by dfsph_correct's
// correction with the given stiffness (the same sum in another order: within float rounding), and both
// builds give the same bytes.
TEST(DfsphJobs, TheBuildAppliesTheWarmStartAsACorrectionPass) {
    const WalledCloud w(10);
    const SortedCloud& cloud = w.cloud;
    const std::size_t n = cloud.size();
    std::vector<float> stiffness(n), vx0(n), vy0(n), vz0(n);
    for (std::size_t i = 0; i < n; ++i) {
        stiffness[i] = 1e-6f * float((i * 7919) % 101);
        vx0[i] = 0.01f * float(i % 13), vy0[i] = -0.02f * float(i % 7), vz0[i] = 0.005f * float(i % 5);
    }
    struct Run {
        Lists l;
        std::vector<float> vx, vy, vz, v4;
        Run(std::size_t n, const std::vector<float>& x, const std::vector<float>& y,
            const std::vector<float>& z)
            : l(n), vx(x), vy(y), vz(z), v4(4 * n) {}
    };
    Run fast(n, vx0, vy0, vz0), baseline(n, vx0, vy0, vz0);
    for (Run* r : {&fast, &baseline}) {
        DfsphParticleOut out = r->l.out();
        out.k_warm = stiffness, out.vx = r->vx, out.vy = r->vy, out.vz = r->vz, out.v4 = r->v4;
        w.build(r->l, out, 0, n, r == &baseline);
    }
    EXPECT_TRUE(same_bytes(fast.vx, baseline.vx) && same_bytes(fast.vy, baseline.vy) &&
                same_bytes(fast.vz, baseline.vz) && same_bytes(fast.v4, baseline.v4));
    // Against the correction pass over the lists just built.
    const Lists& l = fast.l;
    const DfsphContext c{cloud.x, cloud.y, cloud.z, l.x4,      {&l.lists, 1}, l.begin, l.end,
                         l.gx,    l.gy,    l.gz,    l.support, {0, 0, 0},     20.0f};
    std::vector<float> vx = vx0, vy = vy0, vz = vz0, v4(4 * n);
    dfsph_correct(c, 0, 0, n, stiffness, {vx, vy, vz, v4});
    double largest = 0;
    for (std::size_t i = 0; i < n; ++i) {
        largest = std::max({largest, std::abs(double(vx[i]) - vx0[i]), std::abs(double(vy[i]) - vy0[i])});
        EXPECT_NEAR(fast.vx[i], vx[i], 1e-5f) << i;
        EXPECT_NEAR(fast.vy[i], vy[i], 1e-5f) << i;
        EXPECT_NEAR(fast.vz[i], vz[i], 1e-5f) << i;
        EXPECT_EQ(fast.v4[4 * i], fast.vx[i]);
        EXPECT_EQ(fast.v4[4 * i + 3], 0.0f);
    }
    EXPECT_GT(largest, 1e-3) << "the correction moves the velocities";
}

// The prediction's pass also takes the divergence solve's residual: against both computed in double from
// the lists, pair by pair (a compressing, sheared field, so the rate, the viscosity and the stiffness
// all move; particles short of min_support are left out of the residual).
TEST(DfsphJobs, ThePredictionTakesTheDivergenceResidualAndTheViscosity) {
    const WalledCloud w(10);
    const SortedCloud& cloud = w.cloud;
    const std::size_t n = cloud.size();
    Lists l(n);
    w.build(l, l.out(), 0, n, false);
    const float min_support = 20.0f;
    const DfsphContext c{cloud.x, cloud.y, cloud.z, l.x4,      {&l.lists, 1}, l.begin,    l.end,
                         l.gx,    l.gy,    l.gz,    l.support, {0, 0, 0},     min_support};
    std::vector<float> v4(4 * n), k_total(n), k(n), k_warm(n, 0.0f);
    const float centre = 5.0f * 0.93f * WalledCloud::d;
    for (std::size_t i = 0; i < n; ++i) {
        v4[4 * i] = -0.5f * (cloud.x[i] - centre) + 0.3f * cloud.y[i];
        v4[4 * i + 1] = -0.5f * (cloud.y[i] - centre);
        v4[4 * i + 2] = -0.5f * (cloud.z[i] - centre) - 0.2f * cloud.x[i];
        k_total[i] = 1e-7f * float(i % 5);
    }
    std::vector<float> ox(n), oy(n), oz(n), o4(4 * n);
    const float dt = 0.002f, nu = 1e-3f, g[3] = {0.0f, -9.81f, 0.0f};
    const DfsphPredictSums sums = dfsph_predict(c, 0, 0, n, dt, nu, WalledCloud::h, g, v4, k_warm,
                                                {l.factor, k_total, k}, {ox, oy, oz, o4});
    double error = 0, largest_k = 0, largest_a = 0;
    int left_out = 0;
    for (std::size_t i = 0; i < n; ++i) {
        double rate = 0, a[3] = {0, 0, 0};
        for (std::uint32_t p = l.begin[i]; p < l.end[i]; ++p) {
            const DfsphPair q = l.lists.pairs[p];
            double dx[3], dv[3];
            for (int e = 0; e < 3; ++e)
                dx[e] = double(l.x4[4 * i + e]) - l.x4[4 * q.j + e],
                dv[e] = double(v4[4 * i + e]) - v4[4 * q.j + e];
            const double vr = dv[0] * dx[0] + dv[1] * dx[1] + dv[2] * dx[2];
            const double r2 = dx[0] * dx[0] + dx[1] * dx[1] + dx[2] * dx[2];
            rate += double(q.f) * vr;
            for (int e = 0; e < 3; ++e)
                a[e] += 10.0 * nu * vr / (r2 + 0.01 * WalledCloud::h * WalledCloud::h) * double(q.f) * dx[e];
        }
        rate +=
            double(l.gx[i]) * v4[4 * i] + double(l.gy[i]) * v4[4 * i + 1] + double(l.gz[i]) * v4[4 * i + 2];
        const double r = l.support[i] >= min_support ? rate : 0.0;
        left_out += l.support[i] < min_support;
        const double total = k_total[i] + 0.5 * r * l.factor[i];
        const double expect_k = std::max(total, 0.0) - k_total[i];
        EXPECT_NEAR(k[i], expect_k, 1e-4 * std::abs(expect_k) + 1e-12) << i;
        error += std::max(r, 0.0) * dt;
        largest_k = std::max(largest_k, std::abs(expect_k));
        for (int e = 0; e < 3; ++e) {
            const double expect_v = double(v4[4 * i + e]) + dt * (a[e] + g[e]);
            EXPECT_NEAR(o4[4 * i + e], expect_v, 1e-6 * (1.0 + std::abs(expect_v))) << i;
            largest_a = std::max(largest_a, std::abs(a[e]));
        }
        EXPECT_EQ(ox[i], o4[4 * i]);
        EXPECT_EQ(o4[4 * i + 3], 0.0f);
    }
    EXPECT_NEAR(sums.divergence_error, error, 1e-4 * error);
    EXPECT_GT(error, 1e-3) << "the field compresses";
    EXPECT_GT(largest_k, 1e-9) << "the residual moves the stiffness";
    EXPECT_GT(largest_a, 1e-3) << "the shear gives a viscous force";
    EXPECT_GT(left_out, 0) << "the corners are short of support";
    EXPECT_LT(left_out, int(n) / 2);
}

TEST(DfsphJobs, AWarmStartLeftAloneReachesZeroWithoutTurningSubnormal) {
    // Carried at the share every substep and never added to (a droplet in flight): each value on the
    // way is a normal float or exactly zero, and zero is reached.
    for (const float start : {3e-2f, -4e-5f, 1e-8f}) {
        float k = start;
        int steps = 0;
        for (; k != 0.0f && steps < 100000; ++steps) {
            k = dfsph_warm_stiffness(0.8f, k);
            ASSERT_NE(std::fpclassify(k), FP_SUBNORMAL) << start << " after " << steps + 1;
        }
        EXPECT_EQ(k, 0.0f) << start;
        EXPECT_GT(steps, 200) << start;  // it fades, it is not cut off early
    }
    // Where a stiffness acts, the warm start is the plain product.
    for (const float last : {1e-8f, -2.5e-4f, 0.3f})
        for (const float share : {0.8f, 1.7f, 0.05f})
            EXPECT_EQ(dfsph_warm_stiffness(share, last), share * last);
}

}  // namespace
}  // namespace rivulet
