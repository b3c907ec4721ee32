#include "systems/render/screen_fluid.h"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "systems/render/camera.h"
#include "systems/render/gl.h"
#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/screen_fluid_shaders.h"
#include "systems/render/shaders.h"
#include "systems/render/thickness_targets.h"

namespace rivulet {

const char* depth_smoothing_name(DepthSmoothing s) {
    switch (s) {
        case DepthSmoothing::kBilateral:
            return "bilateral";
        case DepthSmoothing::kCurvatureFlow:
            return "curvature-flow";
        case DepthSmoothing::kNarrowRange:
            return "narrow-range";
    }
    return "?";
}

bool parse_depth_smoothing(std::string_view text, DepthSmoothing& out) {
    for (DepthSmoothing s :
         {DepthSmoothing::kBilateral, DepthSmoothing::kCurvatureFlow, DepthSmoothing::kNarrowRange}) {
        if (text == depth_smoothing_name(s)) {
            out = s;
            return true;
        }
    }
    return false;
}

int default_filter_iterations(DepthSmoothing s) {
    switch (s) {
        case DepthSmoothing::kCurvatureFlow:
            return 40;
        case DepthSmoothing::kNarrowRange:
            return 2;
        case DepthSmoothing::kBilateral:
            break;
    }
    return 1;
}

std::string ScreenFluidSettings::validate() const {
    if (smoothing != DepthSmoothing::kBilateral && smoothing != DepthSmoothing::kCurvatureFlow &&
        smoothing != DepthSmoothing::kNarrowRange)
        return "--depth-filter must be bilateral, curvature-flow or narrow-range";
    if (filter_iterations < 0 || filter_iterations > kMaxIterations)
        return fmt::format("--filter-iterations must be in [0, {}], got {}", kMaxIterations,
                           filter_iterations);
    if (!(filter_radius > 0.0f && filter_radius <= 64.0f))
        return fmt::format("--filter-radius must be in (0, 64] particle radii, got {}", filter_radius);
    if (!(depth_sigma > 0.0f && depth_sigma <= 64.0f))
        return fmt::format("depth sigma must be in (0, 64] particle radii, got {}", depth_sigma);
    if (max_filter_pixels < 1 || max_filter_pixels > 128)
        return fmt::format("max filter pixels must be in [1, 128], got {}", max_filter_pixels);
    if (max_filter_taps < 1 || max_filter_taps > 128)
        return fmt::format("max filter taps must be in [1, 128], got {}", max_filter_taps);
    if (fill_holes < 0 || fill_holes > 8)
        return fmt::format("hole filling must be in [0, 8] pixels, got {}", fill_holes);
    if (thickness_downsample < 1 || thickness_downsample > 8)
        return fmt::format("thickness downsampling must be in [1, 8], got {}", thickness_downsample);
    if (!(thickness_blur >= 0.0f && thickness_blur <= 16.0f))
        return fmt::format("thickness blur must be in [0, 16] pixels, got {}", thickness_blur);
    if (spray_neighbours < 0 || spray_neighbours > kMaxSprayNeighbours)
        return fmt::format("--spray must be in [0, {}] neighbours, got {}", kMaxSprayNeighbours,
                           spray_neighbours);
    if (!(spray_distance >= 1.0f && spray_distance <= 16.0f))
        return fmt::format("spray distance must be in [1, 16] particle radii, got {}", spray_distance);
    return {};
}

namespace {

// The uniforms of kScreenCamera a program uses; -1 where the linker dropped one it does not use.
struct CameraUniforms {
    GLint eye = -1, forward = -1, right = -1, up = -1, half_extent = -1, view_proj = -1, viewport = -1;
    void find(GLuint program) {
        eye = glGetUniformLocation(program, "u_eye");
        forward = glGetUniformLocation(program, "u_forward");
        right = glGetUniformLocation(program, "u_right");
        up = glGetUniformLocation(program, "u_up");
        half_extent = glGetUniformLocation(program, "u_half_extent");
        view_proj = glGetUniformLocation(program, "u_view_proj");
        viewport = glGetUniformLocation(program, "u_viewport");
    }
};

struct Program {
    GLuint id = 0;
    CameraUniforms camera;
};

Program build(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment,
              const char* name) {
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex, std::string(name) + ".vert");
    GLuint fs = 0;
    try {
        fs = compile_shader(GL_FRAGMENT_SHADER, fragment, std::string(name) + ".frag");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    Program p;
    p.id = link_program(vs, fs, name);
    p.camera.find(p.id);
    return p;
}

// Uniform locations of one smoothing program; -1 for those it does not have.
struct SmoothingUniforms {
    GLint step = -1, world_sigma = -1, max_radius = -1, max_taps = -1, depth_sigma = -1, threshold = -1,
          clamp = -1, jump = -1, max_step = -1, iterations = -1;
    void find(GLuint p) {
        step = glGetUniformLocation(p, "u_step");
        world_sigma = glGetUniformLocation(p, "u_world_sigma");
        max_radius = glGetUniformLocation(p, "u_max_radius");
        max_taps = glGetUniformLocation(p, "u_max_taps");
        depth_sigma = glGetUniformLocation(p, "u_depth_sigma");
        threshold = glGetUniformLocation(p, "u_threshold");
        clamp = glGetUniformLocation(p, "u_clamp");
        jump = glGetUniformLocation(p, "u_jump");
        max_step = glGetUniformLocation(p, "u_max_step");
        iterations = glGetUniformLocation(p, "u_iterations");
    }
};

Program build_smoothing(DepthSmoothing s) {
    using namespace shaders;
    switch (s) {
        case DepthSmoothing::kBilateral:
            return build({kFullScreenVertex},
                         {kFragmentPrelude, kScreenCamera, kFilterWidth, kBilateralFragment}, "bilateral");
        case DepthSmoothing::kNarrowRange:
            return build({kFullScreenVertex},
                         {kFragmentPrelude, kScreenCamera, kFilterWidth, kNarrowRangeFragment},
                         "narrow_range");
        case DepthSmoothing::kCurvatureFlow:
            return build({kFullScreenVertex}, {kFragmentPrelude, kScreenCamera, kCurvatureFlowFragment},
                         "curvature_flow");
    }
    throw std::invalid_argument("ScreenFluidPass: unknown depth smoothing");
}

using Clock = std::chrono::steady_clock;

// Spray sprites' diameter in particle diameters: smaller than the particle, so drops read as droplets
// rather than as blobs of the water's size.
constexpr float kSpraySize = 0.6f;

// A vertex array reading three float columns as attributes 0-2, advancing per instance (divisor 1) or
// per vertex (0).
GLuint column_vao(std::initializer_list<const GrowingBuffer*> columns, GLuint divisor) {
    GLuint v = 0;
    glGenVertexArrays(1, &v);
    glBindVertexArray(v);
    GLuint a = 0;
    for (const GrowingBuffer* c : columns) {
        glBindVertexBuffer(a, c->id, 0, sizeof(float));
        glVertexBindingDivisor(a, divisor);
        glEnableVertexAttribArray(a);
        glVertexAttribFormat(a, 1, GL_FLOAT, GL_FALSE, 0);
        glVertexAttribBinding(a, a);
        ++a;
    }
    glBindVertexArray(0);
    return v;
}

const ScreenFluidSettings& validated(const ScreenFluidSettings& s) {
    if (const std::string problem = s.validate(); !problem.empty()) throw std::invalid_argument(problem);
    return s;
}

}  // namespace

struct ScreenFluidPass::Impl {
    ScreenFluidSettings settings;
    int width, height, thick_w, thick_h;
    ThicknessTargets thick;  // the chords' sum within their span (thickness_targets.h), then blurred
    Program depth, thickness, close_holes, smoothing, thickness_blur, composite, spray;
    SmoothingUniforms smooth_u;
    GLint depth_radius = -1, depth_push = -1, thickness_radius = -1;
    GLint blur_step = -1, blur_sigma = -1, close_holes_jump = -1, close_holes_gap = -1;
    GLint composite_light = -1, composite_absorption = -1, composite_water = -1,
          composite_has_environment = -1;
    GLint spray_radius = -1, spray_water = -1;
    GLuint depth_a = 0, depth_b = 0, depth_test = 0, thick_b = 0, scene_color = 0, scene_depth = 0;
    GLuint fbo_a = 0, fbo_b = 0, thick_fbo_b = 0;
    GLuint smoothed_fbo = 0, smoothed_texture = 0;  // where the last frame's smoothing ended
    GLuint environment = 0;
    GrowingBuffer xs, ys, zs;
    GLuint vao = 0;
    GrowingBuffer spray_xs, spray_ys, spray_zs;  // one point per particle, not instanced
    GLuint spray_vao = 0;
    CameraBasis basis;
    float aspect = 1;
    ScreenFluidTimings timings;
    Clock::time_point mark_time;

    Impl(int w, int h, const ScreenFluidSettings& s)
        : settings(validated(s)),
          width(w),
          height(h),
          thick_w((w + s.thickness_downsample - 1) / s.thickness_downsample),
          thick_h((h + s.thickness_downsample - 1) / s.thickness_downsample),
          thick(thick_w, thick_h) {
        using namespace shaders;
        depth = build({kVersion, kScreenCamera, kSphereTriangleVertex},
                      {kFragmentPrelude, kScreenCamera, kSphereHit, kSphereDepthFragment}, "fluid_depth");
        thickness =
            build({kVersion, kScreenCamera, kSphereTriangleVertex},
                  {kFragmentPrelude, kScreenCamera, kSphereHit, kSphereThicknessFragment}, "fluid_thickness");
        close_holes =
            build({kFullScreenVertex}, {kFragmentPrelude, kScreenCamera, kCloseHolesFragment}, "close_holes");
        smoothing = build_smoothing(s.smoothing);
        thickness_blur = build({kFullScreenVertex}, {kFragmentPrelude, kScreenCamera, kThicknessBlurFragment},
                               "thickness_blur");
        composite = build({kFullScreenVertex},
                          {kFragmentPrelude, kScreenCamera, kWaterShading, kCompositeFragment}, "composite");
        spray = build({kVersion, kScreenCamera, kSprayVertex},
                      {kFragmentPrelude, kScreenCamera, kSprayFragment}, "spray");
        spray_radius = uniform_location(spray.id, "u_radius", "spray");
        spray_water = uniform_location(spray.id, "u_water_color", "spray");
        glProgramUniform1f(spray.id, uniform_location(spray.id, "u_size", "spray"), kSpraySize);
        depth_radius = uniform_location(depth.id, "u_radius", "fluid_depth");
        depth_push = uniform_location(depth.id, "u_push", "fluid_depth");
        // gl_perspective's window depth, 0.5 + 0.5 ((f + n) / (f - n) - 2 f n / ((f - n) d)), without
        // the matrix: the pass shades every fragment of every sphere.
        const float n = kCameraNear, f = kCameraFar;
        glProgramUniform2f(depth.id, uniform_location(depth.id, "u_window_z", "fluid_depth"),
                           0.5f + 0.5f * (f + n) / (f - n), f * n / (f - n));
        thickness_radius = uniform_location(thickness.id, "u_radius", "fluid_thickness");
        smooth_u.find(smoothing.id);
        blur_step = uniform_location(thickness_blur.id, "u_step", "thickness_blur");
        blur_sigma = uniform_location(thickness_blur.id, "u_sigma", "thickness_blur");
        composite_light = uniform_location(composite.id, "u_light_dir", "composite");
        composite_absorption = uniform_location(composite.id, "u_absorption", "composite");
        composite_water = uniform_location(composite.id, "u_water_color", "composite");
        composite_has_environment = uniform_location(composite.id, "u_has_environment", "composite");

        depth_a = create_texture_2d(GL_R32F, w, h, GL_NEAREST);
        depth_b = create_texture_2d(GL_R32F, w, h, GL_NEAREST);
        depth_test = create_texture_2d(GL_DEPTH_COMPONENT32F, w, h, GL_NEAREST);
        thick_b = create_texture_2d(GL_R32F, thick_w, thick_h, GL_NEAREST);
        scene_color = create_texture_2d(GL_RGBA8, w, h, GL_LINEAR);
        scene_depth = create_texture_2d(GL_DEPTH_COMPONENT24, w, h, GL_NEAREST);
        // The smoothing targets share the depth pass's depth buffer: it tells which pixels hold fluid.
        fbo_a = create_framebuffer({depth_a}, depth_test, "ScreenFluidPass");
        fbo_b = create_framebuffer({depth_b}, depth_test, "ScreenFluidPass");
        thick_fbo_b = create_framebuffer({thick_b}, 0, "ScreenFluidPass");
        smoothed_fbo = fbo_a, smoothed_texture = depth_a;

        xs.create(), ys.create(), zs.create();
        vao = column_vao({&xs, &ys, &zs}, 1);
        spray_xs.create(), spray_ys.create(), spray_zs.create();
        spray_vao = column_vao({&spray_xs, &spray_ys, &spray_zs}, 0);

        // Fixed inputs: texture units (0 depth, 1 thickness, 2 scene colour, 3 scene depth, 4 the
        // environment) and the water's look until set_water.
        const auto unit = [](const Program& p, const char* name, int u) {
            glProgramUniform1i(p.id, uniform_location(p.id, name, "screen fluid"), u);
        };
        unit(composite, "u_depth", 0);
        unit(composite, "u_thickness", 1);
        unit(composite, "u_scene_color", 2);
        unit(composite, "u_scene_depth", 3);
        unit(composite, "u_environment", 4);
        unit(smoothing, "u_depth", 0);
        unit(close_holes, "u_depth", 0);
        glProgramUniform1i(close_holes.id, uniform_location(close_holes.id, "u_reach", "close_holes"),
                           s.fill_holes);
        close_holes_jump = uniform_location(close_holes.id, "u_jump", "close_holes");
        close_holes_gap = uniform_location(close_holes.id, "u_gap", "close_holes");
        unit(thickness_blur, "u_thickness", 0);
        unit(spray, "u_depth", 0);
        set_water(WaterLook{});
        glProgramUniform1i(composite.id, composite_has_environment, 0);
        glProgramUniform1f(composite.id, uniform_location(composite.id, "u_refraction", "composite"),
                           shaders::kRefraction);
        glProgramUniform2f(composite.id, uniform_location(composite.id, "u_near_far", "composite"),
                           kCameraNear, kCameraFar);
        glProgramUniform1i(smoothing.id, smooth_u.max_radius, s.max_filter_pixels);
        glProgramUniform1i(smoothing.id, smooth_u.max_taps, s.max_filter_taps);
        glProgramUniform1i(smoothing.id, smooth_u.iterations, std::max(1, s.filter_iterations));
        glProgramUniform1f(thickness_blur.id, blur_sigma, s.thickness_blur);
        check_gl("ScreenFluidPass setup");
    }

    ~Impl() {
        for (GLuint p : {depth.id, thickness.id, close_holes.id, smoothing.id, thickness_blur.id,
                         composite.id, spray.id})
            glDeleteProgram(p);
        const GLuint textures[] = {depth_a, depth_b, depth_test, thick_b, scene_color, scene_depth};
        glDeleteTextures(6, textures);
        const GLuint fbos[] = {fbo_a, fbo_b, thick_fbo_b};
        glDeleteFramebuffers(3, fbos);
        const GLuint buffers[] = {xs.id, ys.id, zs.id, spray_xs.id, spray_ys.id, spray_zs.id};
        glDeleteBuffers(6, buffers);
        const GLuint vaos[] = {vao, spray_vao};
        glDeleteVertexArrays(2, vaos);
    }

    void set_water(const WaterLook& w) {
        glProgramUniform3f(composite.id, composite_absorption, w.absorption.x, w.absorption.y,
                           w.absorption.z);
        glProgramUniform3f(composite.id, composite_water, w.color.x, w.color.y, w.color.z);
        glProgramUniform3f(spray.id, spray_water, w.color.x, w.color.y, w.color.z);
    }

    void set_environment(GLuint cube_map) {
        environment = cube_map;
        glProgramUniform1i(composite.id, composite_has_environment, cube_map != 0 ? 1 : 0);
    }

    void set_camera(const CameraDesc& camera, Vec3f light) {
        aspect = static_cast<float>(width) / static_cast<float>(height);
        const Mat4 vp = view_projection(camera, aspect);
        basis = camera_basis(camera);
        const CameraBasis& b = basis;
        for (const Program* p :
             {&depth, &thickness, &close_holes, &smoothing, &thickness_blur, &composite, &spray}) {
            const CameraUniforms& u = p->camera;
            glProgramUniform3f(p->id, u.eye, b.eye.x, b.eye.y, b.eye.z);
            glProgramUniform3f(p->id, u.forward, b.forward.x, b.forward.y, b.forward.z);
            glProgramUniform3f(p->id, u.right, b.right.x, b.right.y, b.right.z);
            glProgramUniform3f(p->id, u.up, b.up.x, b.up.y, b.up.z);
            glProgramUniform2f(p->id, u.half_extent, b.tan_half_fov_y * aspect, b.tan_half_fov_y);
            glProgramUniformMatrix4fv(p->id, u.view_proj, 1, GL_FALSE, vp.data());
        }
        glProgramUniform3f(composite.id, composite_light, light.x, light.y, light.z);
    }

    void viewport(const Program& p, int w, int h) {
        glViewport(0, 0, w, h);
        glProgramUniform2f(p.id, p.camera.viewport, static_cast<float>(w), static_cast<float>(h));
    }

    void draw_spheres(const Program& p, std::size_t count) {
        glUseProgram(p.id);
        glBindVertexArray(vao);
        glDrawArraysInstanced(GL_TRIANGLES, 0, 3, static_cast<GLsizei>(count));
    }

    void full_screen(const Program& p) {
        glUseProgram(p.id);
        glBindVertexArray(vao);  // no attribute is read: the triangle comes from gl_VertexID
        glDrawArrays(GL_TRIANGLES, 0, 3);
    }

    // With time_passes: waits for GL and charges the time since the last mark to `slot`.
    void mark(double* slot) {
        if (!settings.time_passes) return;
        glFinish();
        const Clock::time_point now = Clock::now();
        if (slot) *slot = std::chrono::duration<double, std::milli>(now - mark_time).count();
        mark_time = now;
    }

    // The pixels the spheres can cover (x0, y0, x1, y1), from each centre's projection widened by its
    // projected radius: full-screen passes run inside it only.
    std::array<int, 4> screen_bounds(const ParticleSpritesView& p, float radius) const {
        const CameraBasis& b = basis;
        const float half_w = 0.5f * static_cast<float>(width), half_h = 0.5f * static_cast<float>(height);
        const float sx = half_w / (b.tan_half_fov_y * aspect), sy = half_h / b.tan_half_fov_y;
        float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
        bool behind = false;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const Vec3f d = Vec3f{p.x[i], p.y[i], p.z[i]} - b.eye;
            const float z = dot(d, b.forward);
            if (z <= radius) {  // at or behind the eye: it may cover anything
                behind = true;
                break;
            }
            const float inv = 1.0f / (z - radius);
            const float cx = dot(d, b.right) * sx / z, cy = dot(d, b.up) * sy / z;
            const float rx = radius * 1.5f * sx * inv, ry = radius * 1.5f * sy * inv;
            x0 = std::min(x0, cx - rx), x1 = std::max(x1, cx + rx);
            y0 = std::min(y0, cy - ry), y1 = std::max(y1, cy + ry);
        }
        if (behind) return {0, 0, width, height};
        const auto clamp_x = [&](float v) {
            return static_cast<int>(std::clamp(v + half_w, 0.0f, float(width)));
        };
        const auto clamp_y = [&](float v) {
            return static_cast<int>(std::clamp(v + half_h, 0.0f, float(height)));
        };
        return {clamp_x(std::floor(x0)), clamp_y(std::floor(y0)), clamp_x(std::ceil(x1) + 2),
                clamp_y(std::ceil(y1) + 2)};
    }

    // Ping-pongs between depth_a and depth_b; smoothed_fbo / smoothed_texture name where it ends.
    // Pixels outside the scissor box hold no fluid, and both targets are background there.
    // The raw depth is in depth_a; with hole filling the filled depth ends in depth_b. Returns the
    // texture holding the depth smoothing starts from.
    GLuint fill_holes(float radius) {
        if (settings.fill_holes == 0) return depth_a;
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_b);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, depth_a);
        viewport(close_holes, width, height);
        glProgramUniform1f(close_holes.id, close_holes_jump, settings.depth_sigma * radius);
        glProgramUniform1f(close_holes.id, close_holes_gap, radius);
        full_screen(close_holes);
        glDepthFunc(GL_LESS);
        glDisable(GL_DEPTH_TEST);
        return depth_b;
    }

    void smooth(float radius, GLuint start) {
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);  // only where a sphere was drawn (see kFullScreenVertex)
        glDepthMask(GL_FALSE);
        glActiveTexture(GL_TEXTURE0);
        viewport(smoothing, width, height);
        const SmoothingUniforms& u = smooth_u;
        // The filters' passes compound (n Gaussians of sigma / sqrt(n) make one of sigma), so the width is
        // the setting's whatever the passes, as curvature flow's, which spreads it over its steps.
        const bool filter = settings.smoothing != DepthSmoothing::kCurvatureFlow;
        const float passes = static_cast<float>(std::max(1, settings.filter_iterations));
        glProgramUniform1f(smoothing.id, u.world_sigma,
                           settings.filter_radius * radius / (filter ? std::sqrt(passes) : 1.0f));
        glProgramUniform1f(smoothing.id, u.depth_sigma, settings.depth_sigma * radius);
        glProgramUniform1f(smoothing.id, u.threshold, settings.depth_sigma * radius);
        glProgramUniform1f(smoothing.id, u.clamp, radius);
        glProgramUniform1f(smoothing.id, u.jump, settings.depth_sigma * radius);
        glProgramUniform1f(smoothing.id, u.max_step, 0.25f * radius);
        GLuint source = start, other = start == depth_a ? depth_b : depth_a;
        GLuint target_fbo = start == depth_a ? fbo_b : fbo_a, other_fbo = start == depth_a ? fbo_a : fbo_b;
        const auto pass = [&](int sx, int sy) {
            glBindFramebuffer(GL_FRAMEBUFFER, target_fbo);
            glBindTexture(GL_TEXTURE_2D, source);
            if (u.step >= 0) glProgramUniform2i(smoothing.id, u.step, sx, sy);
            full_screen(smoothing);
            std::swap(source, other);
            std::swap(target_fbo, other_fbo);
        };
        for (int i = 0; i < settings.filter_iterations; ++i) {
            if (settings.smoothing == DepthSmoothing::kCurvatureFlow) {
                pass(0, 0);
            } else {
                pass(1, 0);
                pass(0, 1);
            }
        }
        smoothed_texture = source;
        smoothed_fbo = source == depth_a ? fbo_a : fbo_b;
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDisable(GL_DEPTH_TEST);
    }

    void blur_thickness() {
        if (settings.thickness_blur <= 0.0f) return;
        viewport(thickness_blur, thick_w, thick_h);
        glActiveTexture(GL_TEXTURE0);
        glBindFramebuffer(GL_FRAMEBUFFER, thick_fbo_b);
        glBindTexture(GL_TEXTURE_2D, thick.texture());
        glProgramUniform2i(thickness_blur.id, blur_step, 1, 0);
        full_screen(thickness_blur);
        glBindFramebuffer(GL_FRAMEBUFFER, thick.framebuffer());
        glBindTexture(GL_TEXTURE_2D, thick_b);
        glProgramUniform2i(thickness_blur.id, blur_step, 0, 1);
        full_screen(thickness_blur);
    }

    void render(const ParticleSpritesView& particles, const ParticleSpritesView& spray_particles,
                float radius, float spacing) {
        const std::size_t n = particles.size();
        timings = {};
        if ((n == 0 && spray_particles.size() == 0) || radius <= 0) return;
        for (const ParticleSpritesView* v : {&particles, &spray_particles})
            if (v->y.size() != v->size() || v->z.size() != v->size())
                throw std::out_of_range("ScreenFluidPass::render: x, y and z differ in length");
        mark(nullptr);
        if (n > 0) {
            water(particles, radius, screen_depth_radius(radius, spacing));
        } else {  // spray alone: no water hides it
            glBindFramebuffer(GL_FRAMEBUFFER, fbo_a);
            glClearColor(0, 0, 0, 0);
            glClear(GL_COLOR_BUFFER_BIT);
            smoothed_fbo = fbo_a, smoothed_texture = depth_a;
        }
        if (spray_particles.size() > 0) draw_spray(spray_particles, radius);
    }

    // `sphere`: the depth pass's sphere radius (screen_depth_radius), at least `radius`.
    void water(const ParticleSpritesView& particles, float radius, float sphere) {
        const std::size_t n = particles.size();
        xs.upload(particles.x.data(), n * sizeof(float));
        ys.upload(particles.y.data(), n * sizeof(float));
        zs.upload(particles.z.data(), n * sizeof(float));

        copy_scene();

        // Depth of the nearest sphere per pixel; depth_b starts as background too, so pixels outside
        // the smoothing's scissor box read as background whichever target smoothing ends in.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_b);
        glClearColor(0, 0, 0, 0);
        glClear(GL_COLOR_BUFFER_BIT);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_a);
        viewport(depth, width, height);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glEnable(GL_DEPTH_TEST);
        glProgramUniform1f(depth.id, depth_radius, sphere);
        glProgramUniform1f(depth.id, depth_push, sphere - radius);
        draw_spheres(depth, n);
        glDisable(GL_DEPTH_TEST);
        mark(&timings.depth);

        const std::array<int, 4> box = screen_bounds(particles, sphere);
        glEnable(GL_SCISSOR_TEST);
        glScissor(box[0], box[1], box[2] - box[0], box[3] - box[1]);
        smooth(radius, fill_holes(radius));
        glDisable(GL_SCISSOR_TEST);
        mark(&timings.smoothing);

        // Thickness: every sphere's chord, summed, at most the span from the nearest sphere to the farthest
        // (kSphereThicknessFragment), then blurred.
        thick.begin();
        viewport(thickness, thick_w, thick_h);
        glProgramUniform1f(thickness.id, thickness_radius, radius);
        draw_spheres(thickness, n);
        thick.resolve();
        blur_thickness();
        mark(&timings.thickness);

        glEnable(GL_SCISSOR_TEST);  // still the fluid's box
        composite_over_picture();
        glDisable(GL_SCISSOR_TEST);
    }

    // After the composite, into the picture: blended over the water and the scene, depth-tested against
    // the scene's depth without writing it, so the drawing order (particle order) is the only order.
    void draw_spray(const ParticleSpritesView& p, float radius) {
        const std::size_t n = p.size();
        spray_xs.upload(p.x.data(), n * sizeof(float));
        spray_ys.upload(p.y.data(), n * sizeof(float));
        spray_zs.upload(p.z.data(), n * sizeof(float));
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        viewport(spray, width, height);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, smoothed_texture);
        glProgramUniform1f(spray.id, spray_radius, radius);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_FALSE);
        glEnable(GL_BLEND);
        // The picture's alpha stays opaque.
        glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
        glEnable(GL_PROGRAM_POINT_SIZE);
        glUseProgram(spray.id);
        glBindVertexArray(spray_vao);
        glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(n));
        glBindVertexArray(0);
        glDisable(GL_PROGRAM_POINT_SIZE);
        glDisable(GL_BLEND);
        glDepthMask(GL_TRUE);
        mark(&timings.spray);
    }

    // The scene behind: its colour for refraction and its depth for what stands in front of the water.
    void copy_scene() {
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, scene_color);
        glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width, height);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, scene_depth);
        glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width, height);
        mark(&timings.copy_scene);
    }

    void composite_over_picture() {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        viewport(composite, width, height);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, smoothed_texture);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, thick.texture());
        glActiveTexture(GL_TEXTURE4);
        glBindTexture(GL_TEXTURE_CUBE_MAP, environment);
        glDepthMask(GL_FALSE);
        glDisable(GL_DEPTH_TEST);
        full_screen(composite);
        glDepthMask(GL_TRUE);
        glEnable(GL_DEPTH_TEST);
        glActiveTexture(GL_TEXTURE0);
        glBindVertexArray(0);
        mark(&timings.composite);
    }

    void read(ScreenFluidBuffer which, std::span<float> out) const {
        const bool thin = which == ScreenFluidBuffer::kThickness;
        const int w = thin ? thick_w : width, h = thin ? thick_h : height;
        if (out.size() < std::size_t(w) * std::size_t(h))
            throw std::invalid_argument("ScreenFluidPass::read: buffer too small");
        // The raw depth is overwritten by smoothing: only readable as such without filter passes.
        if (which == ScreenFluidBuffer::kRawDepth && settings.filter_iterations > 0)
            throw std::logic_error("ScreenFluidPass::read: the raw depth is smoothed in place");
        glBindFramebuffer(GL_READ_FRAMEBUFFER, thin ? thick.framebuffer() : smoothed_fbo);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, w, h, GL_RED, GL_FLOAT, out.data());
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    }
};

ScreenFluidPass::ScreenFluidPass(int width, int height, const ScreenFluidSettings& settings)
    : impl_(std::make_unique<Impl>(width, height, settings)) {}
ScreenFluidPass::~ScreenFluidPass() = default;

void ScreenFluidPass::set_camera(const CameraDesc& camera, Vec3f light_dir) {
    impl_->set_camera(camera, light_dir);
}
float screen_depth_radius(float radius, float spacing) {
    return spacing > radius ? std::min(spacing, 2.0f * radius) : radius;
}

void ScreenFluidPass::render(const ParticleSpritesView& particles, float radius, float spacing) {
    impl_->render(particles, {}, radius, spacing);
}
void ScreenFluidPass::render(const ParticleSpritesView& fluid, const ParticleSpritesView& spray, float radius,
                             float spacing) {
    impl_->render(fluid, spray, radius, spacing);
}
void ScreenFluidPass::set_water(const WaterLook& water) {
    impl_->set_water(water);
}
void ScreenFluidPass::set_environment(unsigned cube_map_texture) {
    impl_->set_environment(cube_map_texture);
}
void ScreenFluidPass::read(ScreenFluidBuffer which, std::span<float> out) const {
    impl_->read(which, out);
}
const ScreenFluidTimings& ScreenFluidPass::timings() const {
    return impl_->timings;
}
int ScreenFluidPass::thickness_width() const {
    return impl_->thick_w;
}
int ScreenFluidPass::thickness_height() const {
    return impl_->thick_h;
}

}  // namespace rivulet
