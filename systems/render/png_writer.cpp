#include "systems/render/png_writer.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace rivulet {
namespace {

struct PngError {
    char message[256] = {};
};

void on_error(png_structp png, png_const_charp message) {
    auto* error = static_cast<PngError*>(png_get_error_ptr(png));
    std::snprintf(error->message, sizeof error->message, "%s", message);
    png_longjmp(png, 1);
}

void on_warning(png_structp, png_const_charp) {}

// Only plain C objects live in this frame: libpng's longjmp skips destructors. Returns false with
// `error` filled when libpng failed.
bool encode(std::FILE* file, int width, int height, const std::uint8_t* rgba, int zlib_level,
            PngError& error) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, on_error, on_warning);
    if (!png) {
        std::snprintf(error.message, sizeof error.message, "out of memory");
        return false;
    }
    png_infop info = png_create_info_struct(png);
    if (!info || setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, info ? &info : nullptr);
        if (!error.message[0]) std::snprintf(error.message, sizeof error.message, "out of memory");
        return false;
    }
    png_init_io(png, file);
    png_set_compression_level(png, zlib_level);
    // Filtering costs about as much as the fast zlib level saves on rendered pictures: skip it.
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_BASE, PNG_FILTER_TYPE_BASE);
    png_write_info(png, info);
    // Rendered pictures are opaque: libpng drops the fourth byte of each input pixel.
    png_set_filler(png, 0, PNG_FILLER_AFTER);
    const std::size_t stride = std::size_t(width) * 4u;
    for (int y = 0; y < height; ++y) {
        png_write_row(png, rgba + std::size_t(y) * stride);
    }
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return true;
}

}  // namespace

void write_png_rgba(const std::string& path, int width, int height, std::span<const std::uint8_t> rgba,
                    int zlib_level) {
    if (width <= 0 || height <= 0 || rgba.size() < std::size_t(width) * std::size_t(height) * 4u) {
        throw std::runtime_error("write_png_rgba(" + path + "): " + std::to_string(rgba.size()) +
                                 " bytes do not hold a " + std::to_string(width) + "x" +
                                 std::to_string(height) + " RGBA picture");
    }
    if (zlib_level < 0 || zlib_level > 9) {
        throw std::runtime_error("write_png_rgba(" + path + "): zlib level " + std::to_string(zlib_level) +
                                 " is outside [0, 9]");
    }
    std::FILE* file = std::fopen(path.c_str(), "wb");
    if (!file) throw std::runtime_error("cannot open '" + path + "' for writing: " + std::strerror(errno));
    PngError error;
    const bool ok = encode(file, width, height, rgba.data(), zlib_level, error);
    const bool closed = std::fclose(file) == 0;
    if (!ok) throw std::runtime_error("writing PNG '" + path + "' failed: " + error.message);
    if (!closed) throw std::runtime_error("writing PNG '" + path + "' failed: " + std::strerror(errno));
}

}  // namespace rivulet
