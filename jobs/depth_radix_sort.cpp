#include "jobs/depth_radix_sort.h"

#include <algorithm>
#include <array>

namespace rivulet {

namespace {

struct BlockRange {
    std::size_t begin, end;
};

BlockRange block_range(const DepthSortContext& ctx, std::size_t block) {
    const std::size_t begin = block * ctx.block_size;
    return {begin, std::min(ctx.size(), begin + ctx.block_size)};
}

std::span<std::uint32_t> block_counts(const DepthSortContext& ctx, std::size_t block) {
    return ctx.histograms.subspan(block * kRadixDigits, kRadixDigits);
}

constexpr std::uint32_t digit(std::uint32_t key, std::uint32_t pass) {
    return (key >> (pass * kRadixBits)) & (kRadixDigits - 1u);
}

// Up to 2^24 particles (and ctx.max_packed), pass 0 leaves each item as one word, its pass-1 digit above
// its index, so pass 0 writes and pass 1 reads half the bytes; beyond, keys_tmp holds the keys.
constexpr std::uint32_t kIndexBits = 24;
constexpr std::uint32_t kIndexMask = (1u << kIndexBits) - 1u;
static_assert(kRadixPasses == 2 && kRadixBits <= 32 - kIndexBits);

bool packed(const DepthSortContext& ctx) {
    return ctx.size() <= std::min<std::size_t>(ctx.max_packed, std::size_t{1} << kIndexBits);
}

}  // namespace

std::size_t depth_sort_blocks(std::size_t n, std::uint32_t block_size) {
    return (n + block_size - 1) / block_size;
}

void depth_keys_block(const DepthSortContext& ctx, std::span<std::uint32_t> keys, std::size_t block) {
    const auto [begin, end] = block_range(ctx, block);
    const DepthKeyMap& m = ctx.map;
    const float scale = m.scale();
    for (std::size_t i = begin; i < end; ++i)
        keys[i] = m.key_of_depth(m.depth(ctx.x[i], ctx.y[i], ctx.z[i]), scale);
}

void radix_histogram_block(const DepthSortContext& ctx, std::uint32_t pass, std::size_t block) {
    const auto [begin, end] = block_range(ctx, block);
    const std::span<std::uint32_t> counts = block_counts(ctx, block);
    std::fill(counts.begin(), counts.end(), 0u);
    if (pass == 0) {
        for (std::size_t i = begin; i < end; ++i) ++counts[digit(ctx.keys[i], 0)];
    } else if (packed(ctx)) {
        const std::uint32_t* items = ctx.order_tmp.data();
        for (std::size_t i = begin; i < end; ++i) ++counts[items[i] >> kIndexBits];
    } else {
        const std::uint32_t* keys = ctx.keys_tmp.data();
        for (std::size_t i = begin; i < end; ++i) ++counts[digit(keys[i], 1)];
    }
}

void radix_prefix(const DepthSortContext& ctx, std::uint32_t /*pass*/) {
    const std::size_t blocks = depth_sort_blocks(ctx.size(), ctx.block_size);
    // Digit totals first, then one more sweep that hands out cursors: both walk the block-major rows in
    // memory order, where a digit-major walk would stride 8 KiB per step.
    std::array<std::uint32_t, kRadixDigits> base{};
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::span<const std::uint32_t> counts = block_counts(ctx, b);
        for (std::uint32_t d = 0; d < kRadixDigits; ++d) base[d] += counts[d];
    }
    std::uint32_t sum = 0;
    for (std::uint32_t& c : base) {
        const std::uint32_t count = c;
        c = sum;
        sum += count;
    }
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::span<std::uint32_t> counts = block_counts(ctx, b);
        for (std::uint32_t d = 0; d < kRadixDigits; ++d) {
            const std::uint32_t count = counts[d];
            counts[d] = base[d];
            base[d] += count;
        }
    }
}

void radix_scatter_block(const DepthSortContext& ctx, std::uint32_t pass, std::size_t block) {
    const auto [begin, end] = block_range(ctx, block);
    std::uint32_t* cursors = block_counts(ctx, block).data();
    const std::uint32_t* keys = ctx.keys.data();
    std::uint32_t* order_tmp = ctx.order_tmp.data();
    std::uint32_t* order = ctx.order.data();
    // The order before pass 0 is the identity, so it is never stored or read; the last pass writes the
    // order alone (the sorted keys would have no reader).
    if (pass == 0 && packed(ctx)) {
        for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t k = keys[i];
            order_tmp[cursors[digit(k, 0)]++] = digit(k, 1) << kIndexBits | static_cast<std::uint32_t>(i);
        }
    } else if (pass == 0) {
        std::uint32_t* keys_tmp = ctx.keys_tmp.data();
        for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t k = keys[i];
            const std::uint32_t at = cursors[digit(k, 0)]++;
            keys_tmp[at] = k;
            order_tmp[at] = static_cast<std::uint32_t>(i);
        }
    } else if (packed(ctx)) {
        for (std::size_t i = begin; i < end; ++i) {
            const std::uint32_t item = order_tmp[i];
            order[cursors[item >> kIndexBits]++] = item & kIndexMask;
        }
    } else {
        const std::uint32_t* keys_tmp = ctx.keys_tmp.data();
        for (std::size_t i = begin; i < end; ++i) order[cursors[digit(keys_tmp[i], 1)]++] = order_tmp[i];
    }
}

void depth_sort_serial(const DepthSortContext& ctx, std::span<std::uint32_t> keys) {
    const std::size_t blocks = depth_sort_blocks(ctx.size(), ctx.block_size);
    for (std::size_t b = 0; b < blocks; ++b) depth_keys_block(ctx, keys, b);
    for (std::uint32_t pass = 0; pass < kRadixPasses; ++pass) {
        for (std::size_t b = 0; b < blocks; ++b) radix_histogram_block(ctx, pass, b);
        radix_prefix(ctx, pass);
        for (std::size_t b = 0; b < blocks; ++b) radix_scatter_block(ctx, pass, b);
    }
}

}  // namespace rivulet
