// The beads' links by sweeping cells in key order (jobs/grid_links.h) against every pair tested by
// brute force: the same set of pairs, each once with a < b, on a jittered grid with holes and on points
// near their cells' corners (where a link spans the full reach), and rows that hold both ends of each;
// the cells' radix sort (jobs/cell_radix_sort.h) against a stable sort of the keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <set>
#include <tuple>
#include <vector>

#include "jobs/cell_radix_sort.h"
#include "jobs/grid_links.h"

using namespace rivulet;

namespace {

struct Points {
    std::vector<float> x, y, z;
    std::vector<std::uint64_t> key;
    ConstPositions pos() const { return {x, y, z}; }
};

// One point per occupied cell of edge 1, at `fill` density, each at a random place in its cell (or, with
// `corners`, within 0.05 of a corner), in key order; cell indices start at `reach`.
Points grid(int side, double fill, bool corners, std::uint32_t reach, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    Points p;
    for (int k = 0; k < side; ++k)
        for (int j = 0; j < side; ++j)
            for (int i = 0; i < side; ++i) {
                if (u(rng) >= fill) continue;
                float f[3];
                for (float& c : f)
                    c = corners ? (u(rng) < 0.5f ? 0.05f * u(rng) : 0.95f + 0.0499f * u(rng)) : u(rng);
                p.x.push_back(float(i) + f[0]), p.y.push_back(float(j) + f[1]),
                    p.z.push_back(float(k) + f[2]);
                p.key.push_back(pack_cell_key(std::uint64_t(i) + reach, std::uint64_t(j) + reach,
                                              std::uint64_t(k) + reach));
            }
    return p;
}

std::set<std::pair<std::uint32_t, std::uint32_t>> brute_force(const Points& p, float link) {
    std::set<std::pair<std::uint32_t, std::uint32_t>> pairs;
    for (std::uint32_t a = 0; a < p.x.size(); ++a)
        for (std::uint32_t b = a + 1; b < p.x.size(); ++b) {
            const float dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
            if (dx * dx + dy * dy + dz * dz < link * link) pairs.insert({a, b});
        }
    return pairs;
}

void expect_links(const Points& p, float link, std::uint32_t reach) {
    const std::size_t room = 64 * p.x.size();
    std::vector<std::uint32_t> a(room), b(room);
    std::vector<float> length(room);
    const std::size_t n = grid_link_pairs(p.pos(), p.key, reach, link, a, b, length);
    ASSERT_LE(n, room);
    std::set<std::pair<std::uint32_t, std::uint32_t>> found;
    for (std::size_t e = 0; e < n; ++e) {
        EXPECT_LT(a[e], b[e]);
        EXPECT_TRUE(found.insert({a[e], b[e]}).second) << "pair " << a[e] << "-" << b[e] << " twice";
        const float dx = p.x[b[e]] - p.x[a[e]], dy = p.y[b[e]] - p.y[a[e]], dz = p.z[b[e]] - p.z[a[e]];
        EXPECT_FLOAT_EQ(length[e], std::sqrt(dx * dx + dy * dy + dz * dz));
    }
    const auto expected = brute_force(p, link);
    EXPECT_EQ(found, expected);
    ASSERT_GT(expected.size(), p.x.size());  // the case links most points several times

    // Rows: each pair under both of its ends, with its length.
    std::vector<std::uint32_t> first(p.x.size() + 1), to(2 * n);
    std::vector<float> row_length(2 * n);
    link_rows(std::span(a).first(n), std::span(b).first(n), std::span(length).first(n), first, to,
              row_length);
    std::multiset<std::tuple<std::uint32_t, std::uint32_t, float>> rows, want;
    for (std::uint32_t i = 0; i < p.x.size(); ++i)
        for (std::uint32_t e = first[i]; e < first[i + 1]; ++e) rows.insert({i, to[e], row_length[e]});
    for (std::size_t e = 0; e < n; ++e)
        want.insert({a[e], b[e], length[e]}), want.insert({b[e], a[e], length[e]});
    EXPECT_EQ(first.back(), 2 * n);
    EXPECT_EQ(rows, want);

    // Too little room: the count still says how many there are, and what fits is the same prefix.
    std::vector<std::uint32_t> a2(n / 2), b2(n / 2);
    std::vector<float> l2(n / 2);
    EXPECT_EQ(grid_link_pairs(p.pos(), p.key, reach, link, a2, b2, l2), n);
    EXPECT_TRUE(std::equal(a2.begin(), a2.end(), a.begin()) && std::equal(b2.begin(), b2.end(), b.begin()));
}

}  // namespace

TEST(GridLinks, SameAsBruteForceOnAJitteredGridWithHoles) {
    expect_links(grid(9, 0.6, false, 2, 1), 1.5f, 2);
}

TEST(GridLinks, SameAsBruteForceWhereLinksSpanTheWholeReach) {
    // Points near their cells' corners: two cells apart along two axes and still closer than the link.
    expect_links(grid(8, 0.7, true, 2, 2), 1.5f, 2);
    expect_links(grid(7, 0.8, true, 3, 3), 2.5f, 3);
}

TEST(GridLinks, EmptyAndLonePoints) {
    Points none;
    std::vector<std::uint32_t> a(4), b(4);
    std::vector<float> l(4);
    EXPECT_EQ(grid_link_pairs(none.pos(), none.key, 2, 1.5f, a, b, l), 0u);
    const Points far = [] {
        Points p;
        for (int i = 0; i < 3; ++i) {
            p.x.push_back(float(4 * i) + 0.5f), p.y.push_back(0.5f), p.z.push_back(0.5f);
            p.key.push_back(pack_cell_key(std::uint64_t(4 * i) + 2, 2, 2));
        }
        return p;
    }();
    EXPECT_EQ(grid_link_pairs(far.pos(), far.key, 2, 1.5f, a, b, l), 0u);
}

TEST(CellRadixSort, SameOrderAsAStableSortOfTheKeys) {
    // Cells of fields as wide as a pass and wider (two passes of y), with ties to keep in index order.
    std::mt19937 rng(7);
    for (const std::uint32_t max_y : {3u, 2047u, 70000u}) {
        const std::size_t n = 5000;
        std::vector<std::uint64_t> key(n), key_tmp(n), want_key(n);
        std::vector<std::uint32_t> order(n), order_tmp(n), counts(kCellSortDigits), want(n);
        for (auto& k : key) k = pack_cell_key(2 + rng() % 40, 2 + rng() % (max_y - 1), 2 + rng() % 9);
        for (std::uint32_t i = 0; i < n; ++i) want[i] = i;
        std::stable_sort(want.begin(), want.end(),
                         [&](std::uint32_t a, std::uint32_t b) { return key[a] < key[b]; });
        for (std::size_t i = 0; i < n; ++i) want_key[i] = key[want[i]];
        cell_radix_sort({key, key_tmp, order, order_tmp, counts}, 41, max_y, 10);
        EXPECT_EQ(order, want) << "max_y " << max_y;
        EXPECT_EQ(key, want_key) << "max_y " << max_y;
    }
}
