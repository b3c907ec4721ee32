#pragma once
// Byte-order loads and stores built from shifts: file layouts never depend on the host's endianness and
// unaligned buffer positions are fine (compilers fold these into single moves or byte swaps).
#include <bit>
#include <cstddef>
#include <cstdint>

namespace rivulet::io {

template <class U, bool BigEndian>
inline U load_uint(const std::byte* p) {
    U v = 0;
    for (std::size_t i = 0; i < sizeof(U); ++i) {
        const std::size_t shift = 8 * (BigEndian ? sizeof(U) - 1 - i : i);
        v = static_cast<U>(v | static_cast<U>(static_cast<U>(std::to_integer<std::uint8_t>(p[i])) << shift));
    }
    return v;
}

template <class U, bool BigEndian>
inline void store_uint(std::byte* p, U v) {
    for (std::size_t i = 0; i < sizeof(U); ++i) {
        const std::size_t shift = 8 * (BigEndian ? sizeof(U) - 1 - i : i);
        p[i] = static_cast<std::byte>(static_cast<std::uint8_t>(v >> shift));
    }
}

inline void store_f32_le(std::byte* p, float v) {
    store_uint<std::uint32_t, false>(p, std::bit_cast<std::uint32_t>(v));
}
inline void store_f32_be(std::byte* p, float v) {
    store_uint<std::uint32_t, true>(p, std::bit_cast<std::uint32_t>(v));
}
inline void store_u32_le(std::byte* p, std::uint32_t v) {
    store_uint<std::uint32_t, false>(p, v);
}
inline void store_u32_be(std::byte* p, std::uint32_t v) {
    store_uint<std::uint32_t, true>(p, v);
}

}  // namespace rivulet::io
