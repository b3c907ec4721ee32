#include "systems/io/ply_scalar.h"

#include <bit>

#include "systems/io/byte_order.h"

namespace rivulet::io {
namespace {

template <PlyScalar T, bool BigEndian>
double decode(const std::byte* p) {
    if constexpr (T == PlyScalar::int8)
        return static_cast<std::int8_t>(load_uint<std::uint8_t, BigEndian>(p));
    if constexpr (T == PlyScalar::uint8) return load_uint<std::uint8_t, BigEndian>(p);
    if constexpr (T == PlyScalar::int16)
        return static_cast<std::int16_t>(load_uint<std::uint16_t, BigEndian>(p));
    if constexpr (T == PlyScalar::uint16) return load_uint<std::uint16_t, BigEndian>(p);
    if constexpr (T == PlyScalar::int32)
        return static_cast<std::int32_t>(load_uint<std::uint32_t, BigEndian>(p));
    if constexpr (T == PlyScalar::uint32) return load_uint<std::uint32_t, BigEndian>(p);
    if constexpr (T == PlyScalar::float32)
        return std::bit_cast<float>(load_uint<std::uint32_t, BigEndian>(p));
    if constexpr (T == PlyScalar::float64)
        return std::bit_cast<double>(load_uint<std::uint64_t, BigEndian>(p));
}

template <bool BigEndian>
PlyDecoder decoder_for(PlyScalar t) {
    switch (t) {
        case PlyScalar::int8:
            return &decode<PlyScalar::int8, BigEndian>;
        case PlyScalar::uint8:
            return &decode<PlyScalar::uint8, BigEndian>;
        case PlyScalar::int16:
            return &decode<PlyScalar::int16, BigEndian>;
        case PlyScalar::uint16:
            return &decode<PlyScalar::uint16, BigEndian>;
        case PlyScalar::int32:
            return &decode<PlyScalar::int32, BigEndian>;
        case PlyScalar::uint32:
            return &decode<PlyScalar::uint32, BigEndian>;
        case PlyScalar::float32:
            return &decode<PlyScalar::float32, BigEndian>;
        case PlyScalar::float64:
            return &decode<PlyScalar::float64, BigEndian>;
    }
    return nullptr;
}

}  // namespace

std::optional<PlyScalar> ply_scalar_from_name(std::string_view n) {
    if (n == "char" || n == "int8") return PlyScalar::int8;
    if (n == "uchar" || n == "uint8") return PlyScalar::uint8;
    if (n == "short" || n == "int16") return PlyScalar::int16;
    if (n == "ushort" || n == "uint16") return PlyScalar::uint16;
    if (n == "int" || n == "int32") return PlyScalar::int32;
    if (n == "uint" || n == "uint32") return PlyScalar::uint32;
    if (n == "float" || n == "float32") return PlyScalar::float32;
    if (n == "double" || n == "float64") return PlyScalar::float64;
    return std::nullopt;
}

std::size_t ply_scalar_size(PlyScalar t) {
    switch (t) {
        case PlyScalar::int8:
        case PlyScalar::uint8:
            return 1;
        case PlyScalar::int16:
        case PlyScalar::uint16:
            return 2;
        case PlyScalar::int32:
        case PlyScalar::uint32:
        case PlyScalar::float32:
            return 4;
        case PlyScalar::float64:
            return 8;
    }
    return 0;
}

bool ply_scalar_is_integer(PlyScalar t) {
    return t != PlyScalar::float32 && t != PlyScalar::float64;
}

PlyDecoder ply_decoder(PlyScalar t, bool big_endian) {
    return big_endian ? decoder_for<true>(t) : decoder_for<false>(t);
}

}  // namespace rivulet::io
