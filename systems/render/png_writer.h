#pragma once
#include <cstdint>
#include <span>
#include <string>

namespace rivulet {

// Writes an RGBA8 picture (rows top to bottom) as PNG. A fast zlib level by default: encoding costs as
// much as rendering (shared/PLATFORM.md). Throws std::runtime_error on I/O failure.
void write_png_rgba(const std::string& path, int width, int height, std::span<const std::uint8_t> rgba,
                    int zlib_level = 1);

}  // namespace rivulet
