// Spray for the screen-space fluid: neighbour counts of the hashed cell grid against brute force, the
// split stable and the same bytes at 1 and 2 threads, the sprites on real pixels (bright, outside the
// water's depth), and --spray's limits on the command line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <vector>

#include "jobs/chunk_prefix.h"
#include "jobs/spray_split.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/screen_surface.h"
#include "runtime/lib/thread_control.h"
#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/renderer.h"

namespace rivulet {
namespace {

struct Points {
    std::vector<float> x, y, z;
    void add(float a, float b, float c) { x.push_back(a), y.push_back(b), z.push_back(c); }
    std::size_t size() const { return x.size(); }
    ConstPositions view() const { return {x, y, z}; }
    ConstPositions part(std::size_t begin, std::size_t end) const {
        return {std::span(x).subspan(begin, end - begin), std::span(y).subspan(begin, end - begin),
                std::span(z).subspan(begin, end - begin)};
    }
};

// Clusters of a few particles at about SPH spacing, loose drops between them, and a few far away.
Points random_points(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> box(-1.0f, 1.0f), jitter(-0.06f, 0.06f);
    Points p;
    while (p.size() < n) {
        const float cx = box(rng), cy = box(rng), cz = box(rng);
        const int members = 1 + static_cast<int>(rng() % 12);
        for (int k = 0; k < members && p.size() < n; ++k)
            p.add(cx + jitter(rng), cy + jitter(rng), cz + jitter(rng));
        if (rng() % 50 == 0) p.add(cx * 3e7f, cy * 3e7f, 5e7f);  // beyond the grid's cell limit
    }
    return p;
}

// The same squared distance the job computes, over every pair.
std::vector<std::uint32_t> brute_counts(const Points& p, float reach, std::uint32_t cap) {
    std::vector<std::uint32_t> counts(p.size());
    const float reach2 = reach * reach;
    for (std::size_t i = 0; i < p.size(); ++i) {
        std::uint32_t c = 0;
        for (std::size_t j = 0; j < p.size(); ++j) {
            const float ex = p.x[j] - p.x[i], ey = p.y[j] - p.y[i], ez = p.z[j] - p.z[i];
            if (j != i && ex * ex + ey * ey + ez * ez <= reach2) ++c;
        }
        counts[i] = std::min(c, cap);
    }
    return counts;
}

// The four passes serially over chunks of `chunk` particles.
std::vector<std::uint32_t> grid_counts(const Points& p, const SprayGrid& grid, std::size_t chunk,
                                       std::uint32_t cap) {
    const std::size_t n = p.size(), chunks = (n + chunk - 1) / chunk, buckets = grid.buckets();
    std::vector<std::uint64_t> keys(n), cell_key(n);
    std::vector<std::uint32_t> counts(chunks * buckets), cursors(chunks * buckets), start(buckets + 1),
        out(n);
    std::vector<float> cx(n), cy(n), cz(n);
    const auto range = [&](std::size_t c) { return std::pair{c * chunk, std::min(n, (c + 1) * chunk)}; };
    for (std::size_t c = 0; c < chunks; ++c) {
        const auto [b, e] = range(c);
        spray_grid_chunk(grid, p.part(b, e), std::span(keys).subspan(b, e - b),
                         std::span(counts).subspan(c * buckets, buckets));
    }
    EXPECT_EQ(chunk_major_prefix(static_cast<std::uint32_t>(buckets), static_cast<std::uint32_t>(chunks),
                                 buckets, counts, cursors, start),
              n);
    for (std::size_t c = 0; c < chunks; ++c) {
        const auto [b, e] = range(c);
        spray_scatter_chunk(grid, p.part(b, e), std::span(keys).subspan(b, e - b),
                            std::span(cursors).subspan(c * buckets, buckets), {cx, cy, cz, cell_key});
    }
    const SprayCells cells{start, cx, cy, cz, cell_key};
    for (std::size_t c = 0; c < chunks; ++c) {
        const auto [b, e] = range(c);
        const std::uint32_t capped =
            spray_count_chunk(grid, cells, p.part(b, e), std::span(keys).subspan(b, e - b), cap,
                              std::span(out).subspan(b, e - b));
        std::uint32_t want = 0;
        for (std::size_t i = b; i < e; ++i) want += out[i] >= cap ? 1u : 0u;
        EXPECT_EQ(capped, want);
    }
    return out;
}

}  // namespace

TEST(Spray, NeighbourCountsMatchBruteForce) {
    const std::uint32_t unlimited = std::numeric_limits<std::uint32_t>::max() - 1;
    for (std::uint32_t seed : {1u, 2u, 3u}) {
        const Points p = random_points(3000, seed);
        for (float reach : {0.02f, 0.08f, 0.3f}) {
            for (std::uint32_t bits : {6u, SprayGrid::bits_for(p.size())}) {  // 6: many cells per bucket
                const SprayGrid grid{reach, bits};
                for (std::uint32_t cap : {unlimited, 4u, 1u}) {
                    const std::vector<std::uint32_t> want = brute_counts(p, reach, cap);
                    const std::vector<std::uint32_t> got = grid_counts(p, grid, 700, cap);
                    std::size_t wrong = 0, with_neighbours = 0;
                    for (std::size_t i = 0; i < p.size(); ++i)
                        wrong += got[i] != want[i] ? 1 : 0, with_neighbours += want[i] > 0 ? 1 : 0;
                    EXPECT_EQ(wrong, 0u)
                        << "seed " << seed << " reach " << reach << " bits " << bits << " cap " << cap;
                    EXPECT_GT(with_neighbours, p.size() / 10);  // neither all loose drops
                    EXPECT_LT(with_neighbours, p.size());       // nor all water
                }
            }
        }
    }
}

TEST(Spray, NaNPositionsHaveNoNeighbours) {
    Points p;
    p.add(0, 0, 0), p.add(0.01f, 0, 0), p.add(std::nanf(""), 0, 0);
    const std::vector<std::uint32_t> got = grid_counts(p, SprayGrid{0.1f, 6}, 2, 10);
    EXPECT_EQ(got, (std::vector<std::uint32_t>{1, 1, 0}));
}

namespace {

struct SplitResult {
    std::vector<float> fluid_x, fluid_y, fluid_z, spray_x, spray_y, spray_z;
    std::uint64_t hash = 0;
    bool operator==(const SplitResult&) const = default;
};

// One frame of the surface's jobs (stage, then the spray jobs) on `threads` workers.
SplitResult run_split(const Points& p, int threads, int neighbours, float radius) {
    ThreadControl control(threads);
    ScreenFluidSettings s;
    s.spray_neighbours = neighbours;
    ScreenSurface surface(s, p.size(), radius);
    FrameGraph graph;
    const FrameGraph::JobId begin = graph.serial("begin", [] {});
    surface.add_jobs(
        graph, [&p] { return p.view(); }, [] { return 1; }, begin);
    graph.run();
    FrameView v;
    surface.fill_view(1, v);
    const auto copy = [](std::span<const float> c) { return std::vector<float>(c.begin(), c.end()); };
    return {copy(v.sprites.x), copy(v.sprites.y), copy(v.sprites.z),     copy(v.spray.x),
            copy(v.spray.y),   copy(v.spray.z),   surface.output_hash(1)};
}

}  // namespace

TEST(Spray, SplitIsStableAndTheSameAtOneAndTwoThreads) {
    // Several spray chunks (at least 4096 particles each), so chunks meet in the middle of the output.
    const Points p = random_points(14000, 7);
    const float radius = 0.02f, reach = 4 * radius;
    const int threshold = 5;
    const std::vector<std::uint32_t> counts = brute_counts(p, reach, threshold);
    SplitResult want;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const bool fluid = counts[i] >= std::uint32_t(threshold);
        (fluid ? want.fluid_x : want.spray_x).push_back(p.x[i]);
        (fluid ? want.fluid_y : want.spray_y).push_back(p.y[i]);
        (fluid ? want.fluid_z : want.spray_z).push_back(p.z[i]);
    }
    ASSERT_GT(want.fluid_x.size(), p.size() / 4);
    ASSERT_GT(want.spray_x.size(), p.size() / 10);
    SplitResult one = run_split(p, 1, threshold, radius), two = run_split(p, 2, threshold, radius);
    EXPECT_TRUE(one == two);
    want.hash = one.hash;
    EXPECT_TRUE(one == want);  // the particle order kept on both sides
    EXPECT_NE(one.hash, run_split(p, 1, threshold + 1, radius).hash);
}

TEST(Spray, OffKeepsEveryParticleAsWater) {
    const Points p = random_points(500, 9);
    const SplitResult r = run_split(p, 2, 0, 0.02f);
    EXPECT_EQ(r.fluid_x, p.x);
    EXPECT_TRUE(r.spray_x.empty());
}

TEST(Spray, NeedsTheParticleRadius) {
    ScreenFluidSettings s;
    s.spray_neighbours = 4;
    EXPECT_THROW(ScreenSurface(s, 100, 0.0f), std::invalid_argument);
    s.spray_neighbours = ScreenFluidSettings::kMaxSprayNeighbours + 1;
    EXPECT_NE(s.validate().find("--spray"), std::string::npos);
}

namespace {

constexpr int kW = 256, kH = 192;

using test::facing_scene;

// A dense block of particles at SPH spacing (2 radii) and one particle far from it.
Points block_and_drop(float radius, Vec3f drop) {
    Points p;
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 6; ++j)
            for (int k = 0; k < 6; ++k)
                p.add(-0.4f + 2 * radius * float(i), 0.3f + 2 * radius * float(j),
                      -0.2f + 2 * radius * float(k));
    p.add(drop.x, drop.y, drop.z);
    return p;
}

struct Picture {
    std::vector<std::uint8_t> rgba;
    std::vector<float> depth;  // the water's raw depth, rows bottom to top
    std::size_t spray = 0;
};

// Through the surface's jobs and the renderer, as a frame of the pipeline is drawn.
Picture draw(const Points& p, int neighbours, float radius, bool with_particles = true) {
    ScreenFluidSettings s;
    s.spray_neighbours = neighbours;
    s.filter_iterations = 0;  // the raw depth stays readable
    ScreenSurface surface(s, p.size(), radius);
    FrameGraph graph;
    const FrameGraph::JobId begin = graph.serial("begin", [] {});
    surface.add_jobs(
        graph, [&p] { return p.view(); }, [] { return 0; }, begin);
    graph.run();
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(facing_scene());
    r.set_screen_fluid(s);
    FrameView v;
    v.sphere_radius = radius;
    if (with_particles) surface.fill_view(0, v);
    r.render(v);
    Picture out;
    out.rgba.resize(std::size_t(kW) * kH * 4);
    r.read_rgba(out.rgba);
    out.spray = v.spray.size();
    if (with_particles) {
        out.depth.resize(std::size_t(kW) * kH);
        r.screen_fluid().read(ScreenFluidBuffer::kRawDepth, out.depth);
    }
    return out;
}

}  // namespace

TEST(Spray, AnIsolatedParticleIsABrightSpriteOutsideTheWatersDepth) {
    const float radius = 0.05f;
    const Vec3f drop{0.7f, 0.1f, 0.5f};  // in front of the ground, darker than the sky
    const Points p = block_and_drop(radius, drop);
    float px = 0, py = 0;
    ASSERT_TRUE(project_to_pixel(facing_scene().camera, kW, kH, drop, px, py));
    const int x = int(px), y = int(py);  // read_rgba's rows top to bottom; the depth's bottom to top
    const std::size_t rgba_at = (std::size_t(y) * kW + x) * 4, depth_at = std::size_t(kH - 1 - y) * kW + x;

    const Picture empty = draw(p, 4, radius, false);
    const Picture on = draw(p, 4, radius), off = draw(p, 0, radius);
    EXPECT_EQ(on.spray, 1u);
    EXPECT_EQ(off.spray, 0u);
    // On: near white where the drop is, and no water there; the block is water in both.
    for (int c = 0; c < 3; ++c) EXPECT_GE(on.rgba[rgba_at + c], 215) << "channel " << c;
    EXPECT_GT(on.rgba[rgba_at] + on.rgba[rgba_at + 1] + on.rgba[rgba_at + 2],
              empty.rgba[rgba_at] + empty.rgba[rgba_at + 1] + empty.rgba[rgba_at + 2] + 60);
    EXPECT_EQ(on.depth[depth_at], 0.0f);
    // Off: the same particle is a sphere of water in the depth target.
    EXPECT_GT(off.depth[depth_at], 2.0f);
    EXPECT_LT(off.depth[depth_at], 3.5f);
    float bx = 0, by = 0;
    ASSERT_TRUE(project_to_pixel(facing_scene().camera, kW, kH, {-0.4f + 5 * radius, 0.3f + 5 * radius, 0.2f},
                                 bx, by));
    const std::size_t block_at = std::size_t(kH - 1 - int(by)) * kW + int(bx);
    EXPECT_GT(on.depth[block_at], 0.0f);
    EXPECT_EQ(on.depth[block_at], off.depth[block_at]);
    // A sprite is small and casts no shadow: away from its few pixels the picture is the block's alone.
    Points block = p;
    block.x.pop_back(), block.y.pop_back(), block.z.pop_back();
    const Picture alone = draw(block, 4, radius);
    std::size_t changed_far = 0, changed_near = 0;
    for (int yy = 0; yy < kH; ++yy)
        for (int xx = 0; xx < kW; ++xx) {
            const std::size_t k = (std::size_t(yy) * kW + xx) * 4;
            const bool same = std::equal(&on.rgba[k], &on.rgba[k] + 4, &alone.rgba[k]);
            (std::hypot(float(xx) + 0.5f - px, float(yy) + 0.5f - py) < 8 ? changed_near : changed_far) +=
                same ? 0 : 1;
        }
    EXPECT_GT(changed_near, 4u);
    EXPECT_EQ(changed_far, 0u);
}

TEST(Spray, WaterInFrontHidesSpray) {
    const float radius = 0.05f;
    Points p = block_and_drop(radius, {-0.4f + 5 * radius, 0.3f + 5 * radius, -1.0f});  // behind the block
    const Picture with = draw(p, 4, radius);
    p.x.pop_back(), p.y.pop_back(), p.z.pop_back();
    const Picture without = draw(p, 4, radius);
    EXPECT_EQ(with.spray, 1u);
    EXPECT_TRUE(with.rgba == without.rgba);
}

TEST(Spray, BadSprayOptionsAreClearErrors) {
    using rivulet::test::run_cli;
    for (const char* bad : {"-1", "65"}) {
        const auto r = run_cli(std::string("run --method screen --frames 1 --no-render --spray ") + bad);
        EXPECT_NE(r.status, 0) << bad;
        EXPECT_NE(r.output.find("rivulet: error:"), std::string::npos) << r.output;
        EXPECT_NE(r.output.find(std::string("--spray must be in [0, 64] neighbours, got ") + bad),
                  std::string::npos)
            << r.output;
    }
    const auto ok = run_cli("run --method screen --frames 2 --warmup 30 --no-render --spray 6");
    EXPECT_EQ(ok.status, 0) << ok.output;
    EXPECT_NE(ok.output.find("screen.spray_count"), std::string::npos) << ok.output;
}

}  // namespace rivulet
