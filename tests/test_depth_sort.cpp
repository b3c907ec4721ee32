// Depth radix sort of diffuse-object particles: back to front by quantized view depth, stable, and the
// same whatever order the blocks run in.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "jobs/depth_radix_sort.h"

using namespace rivulet;

namespace {

struct Particles {
    std::vector<float> x, y, z;
};

// Depths along (0.6, 0, 0.8) from the origin spread over [-2, 12] while the sort's range is [0, 10], so
// both ends clamp; a third of the positions repeat earlier ones exactly (equal keys, ordered by index).
Particles random_particles(std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> along(-2.0f, 12.0f), across(-5.0f, 5.0f);
    std::uniform_int_distribution<int> coin(0, 2);
    Particles p;
    p.x.resize(n), p.y.resize(n), p.z.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        if (i > 0 && coin(rng) == 0) {
            const std::size_t j = std::uniform_int_distribution<std::size_t>(0, i - 1)(rng);
            p.x[i] = p.x[j], p.y[i] = p.y[j], p.z[i] = p.z[j];
            continue;
        }
        const float d = along(rng), s = across(rng);
        p.x[i] = 0.6f * d - 0.8f * s, p.y[i] = across(rng), p.z[i] = 0.8f * d + 0.6f * s;
    }
    return p;
}

DepthKeyMap test_map() {
    return {{0, 0, 0}, {0.6f, 0.0f, 0.8f}, 0.0f, 10.0f};
}

struct Buffers {
    std::vector<std::uint32_t> keys, keys_tmp, order, order_tmp, histograms;
    DepthSortContext ctx;

    Buffers(const Particles& p, const DepthKeyMap& map, std::uint32_t block_size) {
        const std::size_t n = p.x.size();
        keys.resize(n), keys_tmp.resize(n), order.resize(n), order_tmp.resize(n);
        histograms.resize(depth_sort_blocks(n, block_size) * kRadixDigits);
        ctx = {p.x, p.y, p.z, map, keys, keys_tmp, order, order_tmp, histograms, block_size};
    }
};

// The reference: particle indices stably sorted by their quantized key.
std::vector<std::uint32_t> reference_order(const Particles& p, const DepthKeyMap& map) {
    std::vector<std::uint32_t> order(p.x.size());
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::uint32_t> keys(p.x.size());
    for (std::size_t i = 0; i < keys.size(); ++i) keys[i] = map.key(p.x[i], p.y[i], p.z[i]);
    std::stable_sort(order.begin(), order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    return order;
}

// The parallel schedule with each stage's blocks in a random order, as a thread pool might run them.
void sort_shuffled(const DepthSortContext& ctx, std::span<std::uint32_t> keys, std::uint32_t seed) {
    std::vector<std::size_t> blocks(depth_sort_blocks(ctx.size(), ctx.block_size));
    std::iota(blocks.begin(), blocks.end(), std::size_t{0});
    std::mt19937 rng(seed);
    const auto each = [&](auto&& kernel) {
        std::shuffle(blocks.begin(), blocks.end(), rng);
        for (std::size_t b : blocks) kernel(b);
    };
    each([&](std::size_t b) { depth_keys_block(ctx, keys, b); });
    for (std::uint32_t pass = 0; pass < kRadixPasses; ++pass) {
        each([&](std::size_t b) { radix_histogram_block(ctx, pass, b); });
        radix_prefix(ctx, pass);
        each([&](std::size_t b) { radix_scatter_block(ctx, pass, b); });
    }
}

TEST(DepthKeyMap, FarthestGetsTheSmallestKeyAndEndsClamp) {
    const DepthKeyMap m = test_map();
    EXPECT_EQ(m.key(6.0f, 0, 8.0f), 0u);                    // depth 10: the far end
    EXPECT_EQ(m.key(60.0f, 0, 80.0f), 0u);                  // beyond it
    EXPECT_EQ(m.key(0, 0, 0), kDepthKeyMax);                // depth 0: the near end
    EXPECT_EQ(m.key(-6.0f, 0, -8.0f), kDepthKeyMax);        // in front of it
    EXPECT_LT(m.key(3.0f, 0, 4.0f), m.key(0.6f, 0, 0.8f));  // depth 5 before depth 1
    const float nan = std::numeric_limits<float>::quiet_NaN();
    EXPECT_EQ(m.key(nan, 0, 0), kDepthKeyMax);
    const DepthKeyMap empty{{0, 0, 0}, {0, 0, 1}, 3.0f, 3.0f};
    EXPECT_EQ(empty.key(0, 0, 1), empty.key(0, 0, 7));
}

TEST(DepthRadixSort, MatchesStableSortOfKeys) {
    const Particles p = random_particles(100'003, 7);
    Buffers b(p, test_map(), 4096);
    depth_sort_serial(b.ctx, b.keys);
    EXPECT_EQ(b.order, reference_order(p, test_map()));
    // `keys` still belongs to the particles, in their order.
    for (std::size_t i = 0; i < p.x.size(); i += 997)
        EXPECT_EQ(b.keys[i], test_map().key(p.x[i], p.y[i], p.z[i]));
}

TEST(DepthRadixSort, ShuffledBlocksGiveTheSameOrder) {
    const Particles p = random_particles(50'000, 11);
    Buffers serial(p, test_map(), 1000);
    depth_sort_serial(serial.ctx, serial.keys);
    for (std::uint32_t seed : {1u, 2u, 3u}) {
        Buffers shuffled(p, test_map(), 1000);
        sort_shuffled(shuffled.ctx, shuffled.keys, seed);
        EXPECT_EQ(shuffled.order, serial.order) << "seed " << seed;
    }
}

// Past max_packed (2^24 particles in use) pass 0 keeps keys and indices in two arrays: the same order.
TEST(DepthRadixSort, TwoWordItemsGiveTheSameOrderAsPackedOnes) {
    const Particles p = random_particles(30'011, 5);
    Buffers one_word(p, test_map(), 1000), two_words(p, test_map(), 1000);
    two_words.ctx.max_packed = 0;
    depth_sort_serial(one_word.ctx, one_word.keys);
    sort_shuffled(two_words.ctx, two_words.keys, 9);
    EXPECT_EQ(one_word.order, reference_order(p, test_map()));
    EXPECT_EQ(two_words.order, one_word.order);
}

TEST(DepthRadixSort, SmallAndRaggedSizes) {
    for (std::size_t n : {0u, 1u, 2u, 63u, 64u, 65u, 1000u}) {
        const Particles p = random_particles(n, static_cast<std::uint32_t>(n) + 1u);
        Buffers b(p, test_map(), 64);
        EXPECT_EQ(b.histograms.size(), depth_sort_blocks(n, 64) * kRadixDigits);
        depth_sort_serial(b.ctx, b.keys);
        EXPECT_EQ(b.order, reference_order(p, test_map())) << "n = " << n;
    }
    EXPECT_EQ(depth_sort_blocks(0), 0u);
    EXPECT_EQ(depth_sort_blocks(1), 1u);
    EXPECT_EQ(depth_sort_blocks(kDepthSortBlockSize + 1), 2u);
}

// Equal depths everywhere (an empty range): the order is the particle order.
TEST(DepthRadixSort, EqualKeysKeepIndexOrder) {
    const Particles p = random_particles(5000, 3);
    Buffers b(p, DepthKeyMap{{0, 0, 0}, {0, 0, 1}, 1.0f, 1.0f}, 512);
    depth_sort_serial(b.ctx, b.keys);
    for (std::uint32_t i = 0; i < b.order.size(); ++i) ASSERT_EQ(b.order[i], i);
}

}  // namespace
