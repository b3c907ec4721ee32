#include "systems/render/environment_map.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "systems/render/gl_program.h"

namespace rivulet {
namespace {

Vec3f mix(Vec3f a, Vec3f b, float t) {
    return a + (b - a) * t;
}

int mip_levels(int size) {
    return std::bit_width(static_cast<unsigned>(size));
}

GLuint new_cube_texture(int size) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_CUBE_MAP, t);
    glTexStorage2D(GL_TEXTURE_CUBE_MAP, mip_levels(size), GL_RGBA8, size, size);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glTexParameteri(GL_TEXTURE_CUBE_MAP, wrap, GL_CLAMP_TO_EDGE);
    return t;
}

void upload_face(int face, int size, const std::uint8_t* rgba) {
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(static_cast<GLenum>(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face), 0, 0, 0, size, size, GL_RGBA,
                    GL_UNSIGNED_BYTE, rgba);
}

// Mean of the two middle rows of a side face (+x, -x, +z, -z), the rows either side of the horizon,
// summed over the row's texels, in [0, 1] per channel.
Vec3f middle_row_sum(int face, int size, const std::uint8_t* rgba) {
    if (face == 2 || face == 3) return {};
    const std::size_t row_bytes = std::size_t(size) * 4u;
    const std::uint8_t* below = rgba + std::size_t(size / 2) * row_bytes;
    const std::uint8_t* above = size > 1 ? below - row_bytes : below;
    Vec3f sum;
    for (std::size_t i = 0; i < row_bytes; i += 4) {
        sum = sum + Vec3f{float(above[i] + below[i]), float(above[i + 1] + below[i + 1]),
                          float(above[i + 2] + below[i + 2])};
    }
    return sum * (0.5f / 255.0f);
}

std::uint8_t to_byte(float v) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f));
}

// libpng's simplified reader keeps its state in `image`; this frees it on every way out.
struct PngImage {
    png_image image{};
    PngImage() { image.version = PNG_IMAGE_VERSION; }
    ~PngImage() { png_image_free(&image); }
    PngImage(const PngImage&) = delete;
    PngImage& operator=(const PngImage&) = delete;
};

[[noreturn]] void bad_face(int face, const std::string& path, const std::string& what) {
    throw std::runtime_error("environment face " + std::string(cube_face_name(face)) + " '" + path +
                             "': " + what);
}

// Reads one face as RGBA8 into `out` after checking its size against `size` (0: this face sets it). The
// size is checked from the header, before the pixels are allocated.
void read_face_png(int face, const std::string& path, int& size, std::vector<std::uint8_t>& out) {
    PngImage png;
    if (!png_image_begin_read_from_file(&png.image, path.c_str()))
        bad_face(face, path, std::string("cannot read it as PNG: ") + png.image.message);
    const png_uint_32 w = png.image.width, h = png.image.height;
    const std::string dims = std::to_string(w) + "x" + std::to_string(h);
    if (w != h) bad_face(face, path, "a cube-map face must be square, got " + dims);
    if (w > png_uint_32(kMaxEnvironmentFaceSize))
        bad_face(face, path, dims + " is over the limit of " + std::to_string(kMaxEnvironmentFaceSize) + "²");
    if (size != 0 && w != png_uint_32(size)) {
        bad_face(face, path,
                 "all six faces must be the same size: " + dims + ", face +x is " + std::to_string(size) +
                     "x" + std::to_string(size));
    }
    size = static_cast<int>(w);
    png.image.format = PNG_FORMAT_RGBA;
    out.resize(PNG_IMAGE_SIZE(png.image));
    if (!png_image_finish_read(&png.image, nullptr, out.data(), 0, nullptr))
        bad_face(face, path, std::string("cannot decode it: ") + png.image.message);
}

}  // namespace

const char* cube_face_name(int face) {
    static constexpr std::array<const char*, 6> kNames = {"+x", "-x", "+y", "-y", "+z", "-z"};
    return face >= 0 && face < 6 ? kNames[static_cast<std::size_t>(face)] : "?";
}

Vec3f cube_face_direction(int face, float s, float t) {
    const float sc = 2 * s - 1, tc = 2 * t - 1;
    switch (face) {
        case 0:
            return normalize({1, -tc, -sc});
        case 1:
            return normalize({-1, -tc, sc});
        case 2:
            return normalize({sc, 1, tc});
        case 3:
            return normalize({sc, -1, -tc});
        case 4:
            return normalize({sc, -tc, 1});
        default:
            return normalize({-sc, -tc, -1});
    }
}

Vec3f sky_radiance(Vec3f d, Vec3f sun) {
    // Keep these in step with sky_color() in shaders.cpp.
    constexpr Vec3f kHorizon{0.86f, 0.88f, 0.90f}, kZenith{0.70f, 0.77f, 0.85f};
    constexpr Vec3f kGroundBounce{0.55f, 0.52f, 0.47f}, kSunGlow{1.0f, 0.93f, 0.80f};
    Vec3f c = d.y < 0 ? mix(kHorizon, kGroundBounce, std::clamp(-d.y * 3.0f, 0.0f, 1.0f))
                      : mix(kHorizon, kZenith, std::sqrt(d.y));
    // Broad, so that it stays smooth at kSkyFaceSize; the sun's sharp highlight is the shaders' specular
    // term. Faded out below the horizon, where the floor is.
    const float cos_sun = std::max(dot(d, sun), 0.0f);
    const float above = std::clamp((d.y + 0.05f) * 10.0f, 0.0f, 1.0f);
    const float glow = above * (0.10f * std::pow(cos_sun, 6.0f) + 0.22f * std::pow(cos_sun, 48.0f));
    c = c + kSunGlow * glow;
    return {std::min(c.x, 1.0f), std::min(c.y, 1.0f), std::min(c.z, 1.0f)};
}

EnvironmentMap::~EnvironmentMap() {
    if (texture_) glDeleteTextures(1, &texture_);
}

void EnvironmentMap::replace(GLuint texture, int face_size, Vec3f horizon) {
    glBindTexture(GL_TEXTURE_CUBE_MAP, texture);
    glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
    check_gl("EnvironmentMap (cube map of " + std::to_string(face_size) + "² faces)");
    if (texture_) glDeleteTextures(1, &texture_);
    texture_ = texture;
    face_size_ = face_size;
    horizon_ = horizon;
}

void EnvironmentMap::make_sky(Vec3f sun, int face_size) {
    const GLuint t = new_cube_texture(face_size);
    const auto n = static_cast<std::size_t>(face_size);
    std::vector<std::uint8_t> rgba(n * n * 4u);
    const float inv = 1.0f / static_cast<float>(face_size);
    Vec3f horizon;
    for (int face = 0; face < 6; ++face) {
        for (std::size_t y = 0; y < n; ++y) {
            for (std::size_t x = 0; x < n; ++x) {
                const Vec3f d = cube_face_direction(face, (static_cast<float>(x) + 0.5f) * inv,
                                                    (static_cast<float>(y) + 0.5f) * inv);
                const Vec3f c = sky_radiance(d, sun);
                std::uint8_t* o = &rgba[(y * n + x) * 4u];
                o[0] = to_byte(c.x), o[1] = to_byte(c.y), o[2] = to_byte(c.z), o[3] = 255;
            }
        }
        upload_face(face, face_size, rgba.data());
        horizon = horizon + middle_row_sum(face, face_size, rgba.data());
    }
    replace(t, face_size, horizon * (0.25f / static_cast<float>(face_size)));
}

void EnvironmentMap::load_faces(std::span<const std::string> paths) {
    if (paths.size() != 6) {
        throw std::runtime_error("an environment needs six faces (+x, -x, +y, -y, +z, -z), got " +
                                 std::to_string(paths.size()));
    }
    // One face in memory at a time (six 4096² faces are 400 MB); a bad face drops the new texture.
    int size = 0;
    GLuint t = 0;
    std::vector<std::uint8_t> rgba;
    Vec3f horizon;
    try {
        for (int face = 0; face < 6; ++face) {
            read_face_png(face, paths[std::size_t(face)], size, rgba);
            if (!t) t = new_cube_texture(size);
            glBindTexture(GL_TEXTURE_CUBE_MAP, t);
            upload_face(face, size, rgba.data());
            horizon = horizon + middle_row_sum(face, size, rgba.data());
        }
    } catch (...) {
        if (t) glDeleteTextures(1, &t);
        throw;
    }
    replace(t, size, horizon * (0.25f / static_cast<float>(size)));
}

void EnvironmentMap::read_face(int face, std::span<std::uint8_t> out) const {
    const std::size_t bytes = std::size_t(face_size_) * std::size_t(face_size_) * 4u;
    if (face < 0 || face >= 6 || out.size() < bytes)
        throw std::invalid_argument("EnvironmentMap::read_face: bad face or buffer too small");
    glBindTexture(GL_TEXTURE_CUBE_MAP, texture_);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(static_cast<GLenum>(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face), 0, GL_RGBA, GL_UNSIGNED_BYTE,
                  out.data());
}

}  // namespace rivulet
