#pragma once
// Back-to-front order of particles for alpha-blended point sprites ("Rendering diffuse objects using
// particle systems inside voxelized surface geometry", Juckel & Beckhaus, §4.4: transparent particles
// must be drawn from back to front). The paper sorts with a quick sort; a stable LSD radix sort over
// quantized view depth does the same in linear time and splits into parallel blocks.
//
// Keys: depth d = dot(p - origin, direction), quantized to 16 bits over [depth_min, depth_max] (clamped)
// and inverted, so ascending key = farthest first: over the sprites' 8 m window a key step is 0.12 mm,
// far below a sprite's size. Two passes of 8 bits (256 write streams a block stay in the L1 cache;
// 2,048 did not, and two 11-bit passes of 22-bit keys cost 40 % more), each:
//   radix_histogram_block(pass, b)  for every block b, in parallel
//   radix_prefix(pass)              once, serial
//   radix_scatter_block(pass, b)    for every block b, in parallel
// Each block writes its items of digit d after those of the blocks before it, so the result is the same
// whatever order or thread the blocks run on. Ties keep particle index order.
//
// Buffers, all sized by the caller (nothing here allocates):
//   keys, order, order_tmp: n each; keys_tmp: n where n > min(max_packed, 2^24), else unused;
//   histograms: depth_sort_blocks(n, block_size) * kRadixDigits.
// After pass 1, `order` holds the particle indices back to front; `keys` still holds each particle's own
// key (keys[i] belongs to particle i), and the *_tmp spans hold pass 0's intermediate order (up to 2^24
// particles as one word per item: the pass-1 digit above the index).
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/depth_key_map.h"

namespace rivulet {

inline constexpr std::uint32_t kRadixBits = 8;
inline constexpr std::uint32_t kRadixDigits = 1u << kRadixBits;  // histogram slots per block
inline constexpr std::uint32_t kRadixPasses = kDepthKeyBits / kRadixBits;
// Large enough that the per-block histograms stay small next to the data (1M particles: 64 blocks,
// 64 KiB), small enough to give two threads plenty of blocks to balance.
inline constexpr std::uint32_t kDepthSortBlockSize = 16384;

struct DepthSortContext {
    std::span<const float> x, y, z;  // particle positions, n each
    DepthKeyMap map;
    std::span<const std::uint32_t> keys;        // n, one per particle
    std::span<std::uint32_t> keys_tmp;          // n
    std::span<std::uint32_t> order, order_tmp;  // n each; `order` is the result
    // Block-major, kRadixDigits per block: counts after a histogram pass, write cursors after the prefix.
    std::span<std::uint32_t> histograms;
    std::uint32_t block_size = kDepthSortBlockSize;
    std::size_t max_packed = std::size_t{1} << 24;  // tests lower it to run the two-word path

    // The particles sorted: keys holds one per particle (x, y, z may be empty when the caller made the keys).
    std::size_t size() const { return keys.size(); }
};

// Number of blocks for n particles (0 for n = 0).
std::size_t depth_sort_blocks(std::size_t n, std::uint32_t block_size = kDepthSortBlockSize);

// Parallel over blocks: keys of block b's particles (ctx.x, y, z) into `keys`, the span ctx.keys views.
// Runs first, unless the caller made the keys (the diffuse update makes its sprites' keys).
void depth_keys_block(const DepthSortContext& ctx, std::span<std::uint32_t> keys, std::size_t block);
// Parallel over blocks: counts of block b's digits for `pass` (0: low 8 bits, 1: high 8 bits).
void radix_histogram_block(const DepthSortContext& ctx, std::uint32_t pass, std::size_t block);
// Serial, after every block's histogram of `pass`: turns the counts into each block's write cursors.
void radix_prefix(const DepthSortContext& ctx, std::uint32_t pass);
// Parallel over blocks, after radix_prefix(pass): block b's items to their places. Pass 0 reads `keys`
// (order implied: particle index) and writes keys_tmp/order_tmp; pass 1 reads those and writes `order`.
void radix_scatter_block(const DepthSortContext& ctx, std::uint32_t pass, std::size_t block);

// All kernels in order on the calling thread, the keys made into `keys` first (tests, tools).
void depth_sort_serial(const DepthSortContext& ctx, std::span<std::uint32_t> keys);

}  // namespace rivulet
