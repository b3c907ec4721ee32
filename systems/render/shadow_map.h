#pragma once
// Shadows of the key light: each frame the casters are drawn into a depth texture from the light with an
// orthographic projection fitted around the scene's stage, and the lit shader compares against it with
// a few filtered taps (PCF). Needs the renderer's GL context current.
#include <span>
#include <vector>

#include "jobs/vec3.h"
#include "systems/render/camera.h"
#include "systems/render/gl.h"
#include "systems/scenes/scene.h"

namespace rivulet {

// About one texel per picture pixel where the scenes frame their stage at 1280x720: finer costs llvmpipe
// lookups (2048² made the fountain's frame 5 ms slower) and shows nothing more.
inline constexpr int kShadowMapSize = 1536;

// The one light of every picture (unit, towards the light): above and behind the viewer, to the right,
// so that what faces the camera is lit and shadows fall back and to the left, beside what casts them.
Vec3f key_light(const CameraDesc& camera);

// An axis-aligned rectangle of the ground plane.
struct GroundRect {
    float x0 = 0, z0 = 0, x1 = 0, z1 = 0;
};

struct ShadowFit {
    Mat4 light_view_proj = Mat4::Identity();  // world -> clip of the shadow pass
    Mat4 texture_matrix =
        Mat4::Identity();   // world -> [0, 1]³: shadow-map coordinates and the depth to compare
    float texel_world = 0;  // edge of one shadow-map texel in world units
    float depth_range = 1;  // world units between window depth 0 and 1
    // Where the casters of the stage can shadow the ground plane: the ground outside is drawn without
    // lookups.
    GroundRect ground;
};

// Fits the light's orthographic box around `points` (unit `light`, square texels, room towards the
// light for casters above them); `ground_y` is the plane whose shadowed part is reported.
ShadowFit fit_shadow(Vec3f light, std::span<const Vec3f> points, int resolution, float ground_y);

// What the shadow map must cover: the pool, the SPH tank, the colliders and the emitters (or without a
// pool or a tank, the ground around the camera target), from the ground up to the top of the fluid's
// extent (v_max).
std::vector<Vec3f> shadow_stage(const SceneDesc& scene);

class ShadowMap {
  public:
    explicit ShadowMap(int resolution = kShadowMapSize);
    ~ShadowMap();
    ShadowMap(const ShadowMap&) = delete;
    ShadowMap& operator=(const ShadowMap&) = delete;

    // Binds the depth target, clears it to "lit" and sets the casters' slope-scaled depth offset.
    void begin();
    // Back to the default framebuffer with a width x height viewport.
    void end(int width, int height);

    GLuint texture() const { return texture_; }
    int resolution() const { return resolution_; }

  private:
    int resolution_;
    GLuint texture_ = 0, framebuffer_ = 0;
};

}  // namespace rivulet
