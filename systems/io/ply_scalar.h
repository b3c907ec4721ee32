#pragma once
// PLY scalar property types: names, sizes and decoders from raw file bytes.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace rivulet::io {

enum class PlyScalar : std::uint8_t { int8, uint8, int16, uint16, int32, uint32, float32, float64 };

// Both the classic names (char, uchar, ..., double) and the sized aliases (int8, ..., float64).
std::optional<PlyScalar> ply_scalar_from_name(std::string_view name);
std::size_t ply_scalar_size(PlyScalar t);
bool ply_scalar_is_integer(PlyScalar t);

// Decoders are chosen once per property rather than switching per value in the bulk loops.
using PlyDecoder = double (*)(const std::byte*);
PlyDecoder ply_decoder(PlyScalar t, bool big_endian);

}  // namespace rivulet::io
