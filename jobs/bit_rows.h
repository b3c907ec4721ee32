#pragma once
// Rows of bits for the marching-slices sweep: W 64-bit words a row (W = 1 for blocks of up to 63 cubes,
// 2 up to 127, 3 for 128). Bit i of a corner row is corner column i, of a cube row cube i. The sweep keeps
// its sets (cubes queued and seen per slab, corners computed and inside per slice, edges with a vertex)
// as such rows, so flooding a slab, finding crossed faces and edges, and queueing neighbours are word
// operations on whole rows instead of branches per cube.
#include <cstdint>

namespace rivulet {

template <int W>
struct BitRow {
    std::uint64_t w[W] = {};
};

template <int W>
inline BitRow<W> load_row(const std::uint64_t* p) {
    BitRow<W> r;
    for (int q = 0; q < W; ++q) r.w[q] = p[q];
    return r;
}
template <int W>
inline void store_row(std::uint64_t* p, BitRow<W> r) {
    for (int q = 0; q < W; ++q) p[q] = r.w[q];
}
template <int W>
inline BitRow<W> operator|(BitRow<W> a, BitRow<W> b) {
    for (int q = 0; q < W; ++q) a.w[q] |= b.w[q];
    return a;
}
template <int W>
inline BitRow<W> operator&(BitRow<W> a, BitRow<W> b) {
    for (int q = 0; q < W; ++q) a.w[q] &= b.w[q];
    return a;
}
template <int W>
inline BitRow<W> operator^(BitRow<W> a, BitRow<W> b) {
    for (int q = 0; q < W; ++q) a.w[q] ^= b.w[q];
    return a;
}
// a & ~b
template <int W>
inline BitRow<W> and_not(BitRow<W> a, BitRow<W> b) {
    for (int q = 0; q < W; ++q) a.w[q] &= ~b.w[q];
    return a;
}
// Bit i takes bit i + 1 (the row seen from one column to the left).
template <int W>
inline BitRow<W> shr1(BitRow<W> a) {
    for (int q = 0; q < W; ++q) a.w[q] = a.w[q] >> 1 | (q + 1 < W ? a.w[q + 1] << 63 : 0);
    return a;
}
// Bit i takes bit i - 1.
template <int W>
inline BitRow<W> shl1(BitRow<W> a) {
    for (int q = W - 1; q >= 0; --q) a.w[q] = a.w[q] << 1 | (q > 0 ? a.w[q - 1] >> 63 : 0);
    return a;
}
template <int W>
inline bool any(BitRow<W> a) {
    std::uint64_t o = 0;
    for (int q = 0; q < W; ++q) o |= a.w[q];
    return o != 0;
}
template <int W>
inline std::uint32_t popcount(BitRow<W> a) {
    std::uint32_t c = 0;
    for (int q = 0; q < W; ++q) c += static_cast<std::uint32_t>(__builtin_popcountll(a.w[q]));
    return c;
}
// Bits [0, count).
template <int W>
inline BitRow<W> low_bits(std::uint32_t count) {
    BitRow<W> r;
    for (int q = 0; q < W; ++q) {
        const std::uint32_t lo = 64u * std::uint32_t(q);
        r.w[q] = count >= lo + 64 ? ~std::uint64_t(0)
                 : count > lo     ? (std::uint64_t(1) << (count - lo)) - 1
                                  : 0;
    }
    return r;
}
template <int W>
inline BitRow<W> single_bit(std::uint32_t i) {
    BitRow<W> r;
    r.w[i / 64] = std::uint64_t(1) << (i % 64);
    return r;
}
// Bits i and i + 1 as a two-bit number (i + 1 may lie in the next word).
template <int W>
inline std::uint32_t two_bits(const BitRow<W>& a, std::uint32_t i) {
    if constexpr (W == 1) {
        return static_cast<std::uint32_t>(a.w[0] >> i) & 3u;
    } else {
        const std::uint32_t q = i / 64, s = i % 64;
        std::uint64_t v = a.w[q] >> s;
        if (s == 63 && q + 1 < W) v |= a.w[q + 1] << 1;
        return static_cast<std::uint32_t>(v) & 3u;
    }
}
// f(i) for every set bit i, ascending.
template <int W, class F>
inline void for_each_bit(BitRow<W> a, F&& f) {
    for (int q = 0; q < W; ++q)
        for (std::uint64_t x = a.w[q]; x != 0; x &= x - 1)
            f(64u * std::uint32_t(q) + static_cast<std::uint32_t>(__builtin_ctzll(x)));
}
// Corners where the given corner rows are not all alike (some inside, some outside).
template <int W>
inline BitRow<W> mixed(BitRow<W> a, BitRow<W> b, BitRow<W> c, BitRow<W> d) {
    return and_not(a | b | c | d, a & b & c & d);
}

}  // namespace rivulet
