// Bin sort (Hoetzlein & Höllerer 2009 §2.1): every particle lands in exactly the bins its sphere spans, in
// stable order, whatever the chunking.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "jobs/bin_sort.h"

using namespace rivulet;

namespace {

struct Table {
    std::vector<std::uint32_t> offsets, entries;
    std::vector<float> ex, ey, ez;
};

Table sort_in_chunks(const BinGrid& grid, const std::vector<float>& y, std::uint32_t chunk) {
    const auto n = static_cast<std::uint32_t>(y.size());
    const std::uint32_t chunks = (n + chunk - 1) / chunk;
    std::vector<std::uint32_t> counts(std::size_t(chunks) * grid.bins), cursors(counts.size()), first(n),
        end(n);
    Table t;
    t.offsets.resize(grid.bins + 1);
    for (std::uint32_t c = 0; c < chunks; ++c) {
        const std::uint32_t b = c * chunk, e = std::min(n, b + chunk);
        bin_count_chunk(grid, std::span(y).subspan(b, e - b),
                        std::span(counts).subspan(std::size_t(c) * grid.bins, grid.bins),
                        {std::span(first).subspan(b, e - b), std::span(end).subspan(b, e - b)});
    }
    const std::uint32_t total = bin_prefix(grid.bins, chunks, counts, cursors, t.offsets);
    t.entries.resize(total), t.ex.resize(total), t.ey.resize(total), t.ez.resize(total);
    // x and z are functions of the index so the copied positions can be checked.
    std::vector<float> x(n), z(n);
    for (std::uint32_t i = 0; i < n; ++i) x[i] = static_cast<float>(i), z[i] = -static_cast<float>(i);
    for (std::uint32_t c = 0; c < chunks; ++c) {
        const std::uint32_t b = c * chunk, e = std::min(n, b + chunk);
        const ConstPositions part{std::span(x).subspan(b, e - b), std::span(y).subspan(b, e - b),
                                  std::span(z).subspan(b, e - b)};
        bin_scatter_chunk(part, b, {std::span(first).subspan(b, e - b), std::span(end).subspan(b, e - b)},
                          std::span(cursors).subspan(std::size_t(c) * grid.bins, grid.bins),
                          {t.entries, t.ex, t.ey, t.ez});
    }
    for (std::uint32_t k = 0; k < total; ++k) {
        const std::uint32_t i = t.entries[k];
        if (t.ex[k] != x[i] || t.ey[k] != y[i] || t.ez[k] != z[i])
            ADD_FAILURE() << "entry " << k << " position";
    }
    return t;
}

}  // namespace

TEST(BinSort, EveryParticleInExactlyTheBinsItsSphereSpansInStableOrder) {
    BinGrid grid{2.0f, 0.05f, 41, 0.07f};  // planes from y = 2 down to y = 0
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> dist(-0.3f, 2.3f);  // some particles beyond the domain
    std::vector<float> y(5000);
    for (auto& v : y) v = dist(rng);
    const Table t = sort_in_chunks(grid, y, 777);

    // Reference: a particle belongs to bin b exactly when |y - plane_y(b)| <= radius.
    std::vector<std::vector<std::uint32_t>> expected(grid.bins);
    for (std::uint32_t i = 0; i < y.size(); ++i)
        for (std::uint32_t b = 0; b < grid.bins; ++b)
            if (std::fabs(y[i] - grid.plane_y(b)) <= grid.radius * (1 - 1e-5f)) expected[b].push_back(i);

    for (std::uint32_t b = 0; b < grid.bins; ++b) {
        std::vector<std::uint32_t> got(t.entries.begin() + t.offsets[b],
                                       t.entries.begin() + t.offsets[b + 1]);
        EXPECT_TRUE(std::is_sorted(got.begin(), got.end())) << "bin " << b << " not in particle order";
        // Spheres exactly tangent to a plane may go either way within rounding; everything else must match.
        for (std::uint32_t i : expected[b])
            EXPECT_TRUE(std::binary_search(got.begin(), got.end(), i)) << "bin " << b << " lacks " << i;
        for (std::uint32_t i : got)
            EXPECT_LE(std::fabs(y[i] - grid.plane_y(b)), grid.radius * (1 + 1e-5f))
                << "bin " << b << " has " << i;
    }
}

TEST(BinSort, ChunkingDoesNotChangeTheResult) {
    BinGrid grid{1.0f, 0.01f, 101, 0.025f};
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> dist(0.0f, 1.0f);
    std::vector<float> y(10000);
    for (auto& v : y) v = dist(rng);
    const Table one = sort_in_chunks(grid, y, 10000);
    for (std::uint32_t chunk : {1u, 7u, 1000u, 4096u}) {
        const Table t = sort_in_chunks(grid, y, chunk);
        EXPECT_EQ(t.offsets, one.offsets);
        EXPECT_EQ(t.entries, one.entries);
    }
}

TEST(BinSort, SpheresOutsideTheDomainOrBetweenPlanesLandNowhere) {
    BinGrid grid{1.0f, 0.1f, 11, 0.02f};
    std::uint32_t first = 0, last = 0;
    EXPECT_FALSE(grid.span_of(1.5f, first, last));
    EXPECT_FALSE(grid.span_of(-0.5f, first, last));
    EXPECT_FALSE(grid.span_of(0.95f, first, last));  // between planes 0.9 and 1.0, radius too small
    ASSERT_TRUE(grid.span_of(0.91f, first, last));
    EXPECT_EQ(first, 1u);
    EXPECT_EQ(last, 1u);
    EXPECT_FALSE(grid.span_of(std::nanf(""), first, last));
}

TEST(BinSort, CountPassRangesMatchSpanOfAndAbsurdHeightsLandNowhere) {
    const BinGrid grid{1.0f, 0.1f, 11, 0.07f};
    std::vector<float> y = {1e30f,
                            -1e30f,
                            std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(),
                            std::nanf(""),
                            1.07f,
                            -0.07f,
                            0.5f};
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> height(-0.3f, 1.3f);
    for (int i = 0; i < 1000; ++i) y.push_back(height(rng));
    std::vector<std::uint32_t> counts(grid.bins), first(y.size()), end(y.size());
    bin_count_chunk(grid, y, counts, {first, end});
    std::vector<std::uint32_t> expected(grid.bins);
    for (std::size_t i = 0; i < y.size(); ++i) {
        std::uint32_t lo = 0, hi = 0;
        if (!grid.span_of(y[i], lo, hi)) {
            EXPECT_EQ(first[i], end[i]) << "y " << y[i];
            continue;
        }
        // The plane test itself, in double: every plane in the range is within the radius, and its
        // neighbours outside it are not.
        for (std::uint32_t b = lo; b <= hi; ++b)
            EXPECT_LE(std::abs(double(y[i]) - grid.plane_y(b)), grid.radius + 1e-6);
        if (lo > 0) {
            EXPECT_GT(std::abs(double(y[i]) - grid.plane_y(lo - 1)), grid.radius - 1e-6);
        }
        if (hi + 1 < grid.bins) {
            EXPECT_GT(std::abs(double(y[i]) - grid.plane_y(hi + 1)), grid.radius - 1e-6);
        }
        EXPECT_EQ(first[i], lo);
        EXPECT_EQ(end[i], hi + 1);
        for (std::uint32_t b = lo; b <= hi; ++b) ++expected[b];
    }
    for (std::size_t i = 0; i < 5; ++i) EXPECT_EQ(end[i], 0u) << "absurd height " << y[i];
    EXPECT_EQ(counts, expected);
}
