#include "systems/render/shadow_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

#include "systems/render/gl_program.h"
#include "systems/render/scene_geometry.h"

namespace rivulet {

Vec3f key_light(const CameraDesc& camera) {
    const CameraBasis b = camera_basis(camera);
    Vec3f back = camera.eye - camera.target;
    back.y = 0;
    back = length(back) > 1e-6f ? normalize(back) : Vec3f{0, 0, 1};
    return normalize(Vec3f{0, 1, 0} + back * 0.6f + b.right * 0.35f);
}

ShadowFit fit_shadow(Vec3f light, std::span<const Vec3f> points, int resolution, float ground_y) {
    const Vec3f L = normalize(light), f = L * -1.0f;
    const Vec3f up_guess = std::abs(L.y) > 0.99f ? Vec3f{0, 0, 1} : Vec3f{0, 1, 0};
    const Vec3f r = normalize(cross(f, up_guess)), u = cross(r, f);
    float x0 = 1e30f, x1 = -1e30f, y0 = 1e30f, y1 = -1e30f, z0 = 1e30f, z1 = -1e30f;
    for (Vec3f p : points) {
        const float x = dot(p, r), y = dot(p, u), z = dot(p, L);
        x0 = std::min(x0, x), x1 = std::max(x1, x);
        y0 = std::min(y0, y), y1 = std::max(y1, y);
        z0 = std::min(z0, z), z1 = std::max(z1, z);
    }
    if (points.empty()) x0 = x1 = y0 = y1 = z0 = z1 = 0;
    // Square texels, so a sphere's shadow is round and one texel size describes the map.
    const float extent = std::max({x1 - x0, y1 - y0, 1e-3f}) * 1.02f;
    const float cx = 0.5f * (x0 + x1), cy = 0.5f * (y0 + y1);
    // Casters may rise above the stage (spray over the top of the fluid's extent): plenty of room towards
    // the light costs nothing with an orthographic depth. A little room below for the lowest receivers.
    const float near = z1 + std::max(extent, 2.0f), far = z0 - 0.05f * extent - 0.01f;
    const float s = 2.0f / extent, dz = 2.0f / (near - far);
    ShadowFit fit;
    fit.texel_world = extent / static_cast<float>(resolution);
    fit.depth_range = near - far;
    fit.light_view_proj << r.x * s, r.y * s, r.z * s, -cx * s,  //
        u.x * s, u.y * s, u.z * s, -cy * s,                     //
        -L.x * dz, -L.y * dz, -L.z * dz, -1.0f + near * dz,     //
        0, 0, 0, 1;
    // Clip [-1, 1]³ -> texture [0, 1]³.
    const Eigen::Affine3f to_texture = Eigen::Translation3f(0.5f, 0.5f, 0.5f) * Eigen::Scaling(0.5f);
    fit.texture_matrix = to_texture.matrix() * fit.light_view_proj;
    // Shadows of what lies in the stage fall inside the stage's points slid along the light down to the
    // ground (a light that grazes the ground reaches it everywhere); a little more for the filter's reach.
    if (L.y < 0.05f) {
        fit.ground = {-1e30f, -1e30f, 1e30f, 1e30f};
        return fit;
    }
    fit.ground = {1e30f, 1e30f, -1e30f, -1e30f};
    for (Vec3f p : points) {
        const Vec3f g = p - L * (std::max(p.y - ground_y, 0.0f) / L.y);
        fit.ground.x0 = std::min(fit.ground.x0, g.x), fit.ground.x1 = std::max(fit.ground.x1, g.x);
        fit.ground.z0 = std::min(fit.ground.z0, g.z), fit.ground.z1 = std::max(fit.ground.z1, g.z);
    }
    const float margin = 0.05f + 4.0f * fit.texel_world;
    fit.ground = {fit.ground.x0 - margin, fit.ground.z0 - margin, fit.ground.x1 + margin,
                  fit.ground.z1 + margin};
    return fit;
}

std::vector<Vec3f> shadow_stage(const SceneDesc& scene) {
    std::vector<Vec3f> points;
    const auto box = [&](Vec3f lo, Vec3f hi) {
        for (int i = 0; i < 8; ++i)
            points.push_back({i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z});
    };
    const float ground = scene.ground_y, top = std::max(scene.v_max, ground + 0.1f);
    const Vec3f t = scene.camera.target;
    const PoolDesc& p = scene.pool;
    // Without a pool or a tank to frame the fluid: the ground in front of the camera.
    if (!p.enabled && scene.simulation != SimulationKind::kSph) {
        const float reach = std::max(0.5f, 0.4f * length(scene.camera.eye - t));
        box({t.x - reach, ground, t.z - reach}, {t.x + reach, std::max(top, t.y), t.z + reach});
    }
    if (p.enabled) box({p.x0, ground, p.z0}, {p.x0 + p.size_x, std::max(top, p.level), p.z0 + p.size_z});
    if (scene.simulation == SimulationKind::kSph) {  // the tank over its whole motion, frame included
        const BoxCollider glass = tank_glass_box(scene);
        const float frame = tank_frame_width(scene) + 0.01f;
        const Vec3f a = scene.container_motion.amplitude;
        const Vec3f pad{frame + std::abs(a.x), frame + std::abs(a.y), frame + std::abs(a.z)};
        box(glass.min - pad, glass.max + pad);
    }
    for (const SphereCollider& s : scene.spheres) {
        const Vec3f r{s.radius, s.radius, s.radius};
        box(s.center - r, s.center + r);
    }
    for (const BoxCollider& b : scene.boxes) box(b.min, b.max);
    for (const Emitter& e : scene.emitters) points.push_back(e.position);
    return points;
}

ShadowMap::ShadowMap(int resolution) : resolution_(resolution) {
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT24, resolution, resolution);
    // Linear filtering of a comparison gives each tap a 2x2 percentage-closer filter for free.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
    const float lit[4] = {1, 1, 1, 1};
    glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, lit);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    glGenFramebuffers(1, &framebuffer_);
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, texture_, 0);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (!complete) throw std::runtime_error("ShadowMap: the depth target is incomplete");
    check_gl("ShadowMap setup");
}

ShadowMap::~ShadowMap() {
    glDeleteFramebuffers(1, &framebuffer_);
    glDeleteTextures(1, &texture_);
}

void ShadowMap::begin() {
    glBindFramebuffer(GL_FRAMEBUFFER, framebuffer_);
    glViewport(0, 0, resolution_, resolution_);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClear(GL_DEPTH_BUFFER_BIT);
    // Slope-scaled: a caster's depth is pushed away from the light the more it is tilted, so its own lit
    // surface never compares as behind itself (acne); the shader's normal offset covers the rest.
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.5f, 4.0f);
}

void ShadowMap::end(int width, int height) {
    glDisable(GL_POLYGON_OFFSET_FILL);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width, height);
}

}  // namespace rivulet
