#pragma once
// The scene's surroundings as a GL cube map: what the sky pass draws behind everything and what water and
// glass reflect, so a loaded environment shows up in both. Made at start-up from the analytic sky, or
// loaded from six PNG faces (scene files: docs/scenes.md). Needs the renderer's GL context current.
#include <cstdint>
#include <span>
#include <string>

#include "jobs/vec3.h"
#include "systems/render/gl.h"

namespace rivulet {

// The made sky is smooth, so a small face suffices: it is magnified with linear filtering.
inline constexpr int kSkyFaceSize = 128;
// Six 4096² RGBA faces are 400 MB of texture already.
inline constexpr int kMaxEnvironmentFaceSize = 4096;

// Faces in GL order (GL_TEXTURE_CUBE_MAP_POSITIVE_X + i), also the order of scene files: "+x", "-x", "+y",
// "-y", "+z", "-z".
const char* cube_face_name(int face);

// Unit direction through the point (s, t) of `face`, both in [0, 1]; t = 0 is the face's first row (the
// top row of a face image). The OpenGL cube-map convention, which the usual skybox image sets follow.
Vec3f cube_face_direction(int face, float s, float t);

// The made sky, linear RGB in [0, 1]: pale blue above, a floor-coloured bounce below the horizon, and a
// broad glow towards the key light `sun` (unit) so that water turned towards it brightens. The fragment
// prelude's sky_color() (shaders.cpp) is the same sky without the glow, for passes that have no cube map.
Vec3f sky_radiance(Vec3f dir, Vec3f sun);

class EnvironmentMap {
  public:
    EnvironmentMap() = default;
    ~EnvironmentMap();
    EnvironmentMap(const EnvironmentMap&) = delete;
    EnvironmentMap& operator=(const EnvironmentMap&) = delete;

    // Both replace the texture (its name changes: hand texture() again to whoever samples it).
    // Fills `face_size`² texels per face with sky_radiance.
    void make_sky(Vec3f sun, int face_size = kSkyFaceSize);
    // Six PNG files, faces +x, -x, +y, -y, +z, -z: square, all the same size, at most
    // kMaxEnvironmentFaceSize. Throws std::runtime_error naming the face and the file when one cannot be
    // read, is not a PNG, or has the wrong size; the previous texture is then kept.
    void load_faces(std::span<const std::string> paths);

    GLuint texture() const { return texture_; }
    int face_size() const { return face_size_; }
    // Mean colour along the horizon (the middle rows of the four side faces): what the ground fades into
    // far away, as one colour because a per-pixel cube-map lookup there costs llvmpipe a lot.
    Vec3f horizon_color() const { return horizon_; }
    // Level 0 of `face` as RGBA8, face_size()² texels, rows in order of t (the first row first).
    void read_face(int face, std::span<std::uint8_t> out) const;

  private:
    void replace(GLuint texture, int face_size, Vec3f horizon);

    GLuint texture_ = 0;
    int face_size_ = 0;
    Vec3f horizon_;
};

}  // namespace rivulet
