// SPH neighbour grid (jobs/sph_grid.h): the cell-sorted particles are a stable permutation (ids travel
// with them), identical for any chunking, and the 27-cell search finds exactly the brute-force
// neighbours within h on random sets, including points outside the grid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "jobs/counter_rng.h"
#include "jobs/sph_grid.h"

namespace rivulet {
namespace {

struct Cloud {
    std::vector<float> x, y, z, vx, vy, vz;
    std::vector<std::uint32_t> id;
};

Cloud random_cloud(std::size_t n, std::uint64_t seed, float lo, float hi) {
    Cloud c;
    for (std::size_t i = 0; i < n; ++i) {
        auto u = [&](std::uint64_t s) { return lo + (hi - lo) * counter_uniform(seed, 0, i, s); };
        c.x.push_back(u(0)), c.y.push_back(u(1)), c.z.push_back(u(2));
        c.vx.push_back(u(3)), c.vy.push_back(u(4)), c.vz.push_back(u(5));
        c.id.push_back(static_cast<std::uint32_t>(1000 + i));
    }
    return c;
}

struct Sorted {
    std::vector<float> x, y, z, vx, vy, vz;
    std::vector<std::uint32_t> id, key, cell_start;
};

// Counts and cursors start as garbage: a chunk may read and write only the cells its particles are in.
Sorted sort_in_chunks(const SphGrid& g, const Cloud& c, std::uint32_t chunks) {
    const std::size_t n = c.x.size();
    const std::uint32_t cells = g.cells();
    std::vector<std::uint32_t> keys(n), counts(std::size_t(chunks) * cells, 0xdeadbeefu),
        cursors(counts.size(), 0xdeadbeefu);
    std::vector<SphKeyRange> ranges(chunks);
    Sorted s;
    s.x.resize(n), s.y.resize(n), s.z.resize(n), s.vx.resize(n), s.vy.resize(n), s.vz.resize(n);
    s.id.resize(n), s.key.resize(n), s.cell_start.resize(cells + 1);
    auto begin = [&](std::uint32_t k) { return k * n / chunks; };
    // Chunks in reverse order: the result must not depend on the schedule.
    for (std::uint32_t k = chunks; k-- > 0;) {
        const std::size_t b = begin(k), len = begin(k + 1) - b;
        ranges[k] = sph_grid_count_chunk(g, std::span(c.x).subspan(b, len), std::span(c.y).subspan(b, len),
                                         std::span(c.z).subspan(b, len), std::span(keys).subspan(b, len),
                                         std::span(counts).subspan(std::size_t(k) * cells, cells));
        for (std::size_t i = b; i < b + len; ++i) {
            EXPECT_GE(keys[i], ranges[k].begin);
            EXPECT_LT(keys[i], ranges[k].end);
        }
    }
    // Cursors over uneven cell ranges, last range first.
    std::vector<std::uint32_t> totals(cells);
    const std::uint32_t cuts[] = {0, cells / 3, cells / 3 + 1, cells};
    for (int r = 2; r >= 0; --r)
        sph_grid_cursors(cells, ranges, cuts[r], cuts[r + 1], counts, cursors, totals);
    EXPECT_EQ(sph_grid_offsets(totals, s.cell_start), n);
    const SphSortedOut out{s.x, s.y, s.z, s.vx, s.vy, s.vz, s.id, s.key};
    for (std::uint32_t k = chunks; k-- > 0;) {
        const std::size_t b = begin(k), len = begin(k + 1) - b;
        const SphParticlesIn in{std::span(c.x).subspan(b, len),  std::span(c.y).subspan(b, len),
                                std::span(c.z).subspan(b, len),  std::span(c.vx).subspan(b, len),
                                std::span(c.vy).subspan(b, len), std::span(c.vz).subspan(b, len),
                                std::span(c.id).subspan(b, len)};
        sph_grid_scatter_chunk(in, std::span(keys).subspan(b, len), s.cell_start,
                               std::span(cursors).subspan(std::size_t(k) * cells, cells), out);
    }
    return s;
}

TEST(SphNeighbours, SortIsAStablePermutationByCellForAnyChunking) {
    const Cloud c = random_cloud(3000, 7, 0.0f, 1.0f);
    const SphGrid g{{0, 0, 0}, 0.1f, 10, 10, 10};
    const Sorted one = sort_in_chunks(g, c, 1);
    for (std::uint32_t chunks : {2u, 7u, 64u}) {
        const Sorted s = sort_in_chunks(g, c, chunks);
        EXPECT_EQ(s.id, one.id) << chunks;
        EXPECT_EQ(s.x, one.x) << chunks;
        EXPECT_EQ(s.cell_start, one.cell_start) << chunks;
    }
    // Sorted once already, as the simulation's particles are at each substep: every chunk's cells are
    // a narrow range, and sorting again changes nothing.
    Cloud again{one.x, one.y, one.z, one.vx, one.vy, one.vz, one.id};
    for (std::uint32_t chunks : {1u, 7u, 64u}) {
        const Sorted s = sort_in_chunks(g, again, chunks);
        EXPECT_EQ(s.id, one.id) << chunks;
        EXPECT_EQ(s.cell_start, one.cell_start) << chunks;
    }
    // Keys ascend; within a cell, original order (ids ascend); every id once, with its own data.
    for (std::size_t i = 1; i < one.id.size(); ++i) {
        ASSERT_LE(one.key[i - 1], one.key[i]);
        if (one.key[i - 1] == one.key[i]) {
            ASSERT_LT(one.id[i - 1], one.id[i]);
        }
    }
    for (std::size_t i = 0; i < one.id.size(); ++i) {
        const std::size_t src = one.id[i] - 1000;
        ASSERT_EQ(one.x[i], c.x[src]);
        ASSERT_EQ(one.vz[i], c.vz[src]);
        ASSERT_EQ(one.key[i], g.key(c.x[src], c.y[src], c.z[src]));
        const std::uint32_t k = one.key[i];
        ASSERT_GE(i, one.cell_start[k]);
        ASSERT_LT(i, one.cell_start[k + 1]);
    }
}

TEST(SphNeighbours, GridSearchEqualsBruteForce) {
    for (std::uint64_t seed : {1u, 2u, 3u}) {
        const float h = 0.07f + 0.02f * static_cast<float>(seed);
        // Some points lie outside the grid (clamped into border cells); the search must still be exact
        // for points inside it, which is what the simulation guarantees.
        const Cloud c = random_cloud(2500, seed, -0.05f, 1.05f);
        SphGrid g;
        g.origin = {0, 0, 0};
        g.cell = h;
        g.nx = g.ny = g.nz = static_cast<std::uint32_t>(std::ceil(1.0f / h));
        const Sorted s = sort_in_chunks(g, c, 5);
        const float h2 = h * h;
        std::size_t pairs = 0;
        for (std::size_t i = 0; i < s.id.size(); ++i) {
            const bool inside =
                s.x[i] >= 0 && s.y[i] >= 0 && s.z[i] >= 0 && s.x[i] < 1 && s.y[i] < 1 && s.z[i] < 1;
            if (!inside) continue;
            std::vector<std::uint32_t> grid, brute;
            sph_for_each_near(g, s.cell_start, s.key[i], [&](std::uint32_t j) {
                const float dx = s.x[i] - s.x[j], dy = s.y[i] - s.y[j], dz = s.z[i] - s.z[j];
                if (dx * dx + dy * dy + dz * dz < h2) grid.push_back(s.id[j]);
            });
            for (std::size_t j = 0; j < s.id.size(); ++j) {
                const float dx = s.x[i] - s.x[j], dy = s.y[i] - s.y[j], dz = s.z[i] - s.z[j];
                if (dx * dx + dy * dy + dz * dz < h2) brute.push_back(s.id[j]);
            }
            std::vector<std::uint32_t> sorted_grid = grid;
            std::sort(sorted_grid.begin(), sorted_grid.end());
            std::sort(brute.begin(), brute.end());
            ASSERT_EQ(std::adjacent_find(sorted_grid.begin(), sorted_grid.end()), sorted_grid.end());
            ASSERT_EQ(sorted_grid, brute) << "particle " << s.id[i];
            pairs += brute.size();
        }
        EXPECT_GT(pairs, 2500u * 3u);  // the sets are dense enough to test something
    }
}

}  // namespace
}  // namespace rivulet
