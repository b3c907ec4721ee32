#include "systems/render/volume_pass.h"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <vector>

#include "systems/render/camera.h"
#include "systems/render/gl.h"
#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/screen_fluid_shaders.h"
#include "systems/render/shaders.h"
#include "systems/render/volume_shaders.h"

namespace rivulet {

std::string VolumeRaycastSettings::validate() const {
    if (!(step > 0.0f && step <= 0.5f))
        return fmt::format("volume ray step must be in (0, 0.5] voxels, got {}", step);
    if (refine < 0 || refine > kMaxRefine)
        return fmt::format("volume ray refinement must be in [0, {}] bisection steps, got {}", kMaxRefine,
                           refine);
    return {};
}

namespace {

using Clock = std::chrono::steady_clock;

// Behind the surface the rays step this many voxels: the thickness only tints the water, so it need not
// resolve what the surface search must.
constexpr float kThicknessStep = 2.0f;
// Thickness beyond which the absorbed colour no longer changes in 8 bits: exp(-a t) < 1/512.
constexpr float kSaturatedTransmission = 512.0f;
// shade_water shifts the scene behind by at most this much of the picture along each axis (kRefraction
// times the thickness it caps at 0.2, times a unit normal's screen part).
constexpr float kRefractionReach = shaders::kRefraction * 0.2f;
constexpr float kNoClip = 1e30f;
constexpr int kSpanUnit = 8;
// The shell is made of blocks of kBlockCells^3 cells, finer than a brick: a ray starts at most a block
// from the surface instead of a brick, which halves and halves again what it marches, for more faces to
// rasterise and a pass over the surface bricks' samples here.
constexpr std::uint32_t kBlockCells = 2;
constexpr std::uint32_t kBlocksPerBrick = kBrickCells / kBlockCells;
static_assert(kBrickCells % kBlockCells == 0);

// Pixels [x0, x1) x [y0, y1), rows from the bottom.
struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
};

Rect united(Rect a, Rect b) {
    if (a.empty()) return b;
    if (b.empty()) return a;
    return {std::min(a.x0, b.x0), std::min(a.y0, b.y0), std::max(a.x1, b.x1), std::max(a.y1, b.y1)};
}

// Vertex stage kVersion + kScreenCamera + `vertex` (or kFullScreenVertex alone); fragment stage
// kFragmentPrelude + kScreenCamera + `fragment`, in order.
GLuint build(const char* vertex, std::initializer_list<const char*> fragment, const char* name) {
    using namespace shaders;
    const GLuint vs =
        vertex
            ? compile_shader(GL_VERTEX_SHADER, {kVersion, kScreenCamera, vertex}, std::string(name) + ".vert")
            : compile_shader(GL_VERTEX_SHADER, {kFullScreenVertex}, std::string(name) + ".vert");
    GLuint fs = 0;
    try {
        std::string text = std::string(kFragmentPrelude) + kScreenCamera;
        for (const char* part : fragment) text += part;
        fs = compile_shader(GL_FRAGMENT_SHADER, {text.c_str()}, std::string(name) + ".frag");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    return link_program(vs, fs, name);
}

const VolumeRaycastSettings& validated(const VolumeRaycastSettings& s) {
    if (const std::string problem = s.validate(); !problem.empty()) throw std::invalid_argument(problem);
    return s;
}

[[noreturn]] void bad_volume(const std::string& what) {
    throw std::out_of_range("VolumePass::upload: " + what);
}

GLuint create_texture_3d(GLenum filter) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_3D, t);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
    for (GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R})
        glTexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_BASE_LEVEL, 0);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_3D, 0);
    return t;
}

// kScreenCamera's uniforms of a program; -1 where the linker dropped one it does not use.
struct CameraUniforms {
    GLint eye = -1, forward = -1, right = -1, up = -1, half_extent = -1, view_proj = -1, viewport = -1;
    explicit CameraUniforms(GLuint p)
        : eye(glGetUniformLocation(p, "u_eye")),
          forward(glGetUniformLocation(p, "u_forward")),
          right(glGetUniformLocation(p, "u_right")),
          up(glGetUniformLocation(p, "u_up")),
          half_extent(glGetUniformLocation(p, "u_half_extent")),
          view_proj(glGetUniformLocation(p, "u_view_proj")),
          viewport(glGetUniformLocation(p, "u_viewport")) {}
};

// Faces of a block, as kVolumeShellVertex numbers them.
enum Face : std::uint32_t { kMinusX, kPlusX, kMinusY, kPlusY, kMinusZ, kPlusZ };

}  // namespace

struct VolumePass::Impl {
    VolumeRaycastSettings settings;
    int width, height;
    GLuint shell = 0, raycast = 0;
    GLint u_origin = -1, u_voxel = -1, u_grid = -1, u_max_bricks = -1, u_ray_lo = -1, u_ray_hi = -1,
          u_atlas_scale = -1, u_iso = -1, u_light = -1, u_has_environment = -1, u_reflection_lod = -1,
          u_absorption = -1, u_water_color = -1, u_thickness_cap = -1, u_use_span = -1;
    GLint shell_origin = -1, shell_block = -1, shell_blocks = -1;
    // The rays' targets: the picture (the scene copied in, the water drawn over it, then blitted back),
    // the hit's depth and the thickness, with the shell's depth buffer to skip what it does not cover.
    GLuint color_target = 0, depth_target = 0, thickness_target = 0, fbo = 0;
    GLuint span_target = 0, shell_depth = 0, span_fbo = 0;
    GLuint scene_color = 0, scene_depth = 0;  // what the rays read: refraction, and where solids stop them
    GLuint environment = 0;
    GLuint empty_vao = 0;  // the full-screen triangle comes from gl_VertexID
    GLuint shell_vao = 0;
    GrowingBuffer shell_buffer;
    std::vector<std::uint32_t> shell_faces;    // block index * 8 + face
    std::vector<std::uint8_t> block_occupied;  // per block of the grid (x fastest): may hold the surface
    std::vector<std::uint32_t> occupied_blocks;
    GLint max_3d_size = 0;

    // The atlas holds atlas_layer_capacity layers and only grows; the brick table only grows per axis.
    GLuint atlas = 0;
    std::uint32_t atlas_layer_capacity = 0;
    GLuint bricks = 0;
    std::array<std::uint32_t, 3> brick_capacity{0, 0, 0};
    std::vector<float> brick_table;  // RGBA per brick: slot, least, greatest, unused

    // The last upload.
    DensityGrid grid;
    std::uint32_t stored = 0;

    Vec3f clip_lo{-kNoClip, -kNoClip, -kNoClip}, clip_hi{kNoClip, kNoClip, kNoClip};
    CameraBasis basis;
    Mat4 view_proj = Mat4::Zero();
    Rect dirty;  // where the depth and thickness targets may still hold an earlier frame's hits

    VolumeTimings timings;
    Clock::time_point mark_time;

    Impl(int w, int h, const VolumeRaycastSettings& s) : settings(validated(s)), width(w), height(h) {
        using namespace shaders;
        const std::string layout = volume_layout_glsl();
        shell = build(kVolumeShellVertex, {kVolumeShellFragment}, "volume_shell");
        raycast = build(nullptr, {kWaterShading, layout.c_str(), kVolumeRaycastFragment}, "volume_raycast");
        shell_origin = uniform_location(shell, "u_origin", "volume_shell");
        shell_block = uniform_location(shell, "u_block", "volume_shell");
        shell_blocks = uniform_location(shell, "u_blocks", "volume_shell");
        const auto find = [&](const char* name) { return uniform_location(raycast, name, "volume_raycast"); };
        u_origin = find("u_origin"), u_voxel = find("u_voxel"), u_grid = find("u_grid");
        u_max_bricks = find("u_max_bricks"), u_ray_lo = find("u_ray_lo"), u_ray_hi = find("u_ray_hi");
        u_atlas_scale = find("u_atlas_scale"), u_iso = find("u_iso"), u_light = find("u_light_dir");
        u_has_environment = find("u_has_environment"), u_reflection_lod = find("u_reflection_lod");
        u_absorption = find("u_absorption"), u_water_color = find("u_water_color");
        u_thickness_cap = find("u_thickness_cap"), u_use_span = find("u_use_span");

        // Fixed inputs: texture units (0 atlas, 1 brick table, 2 scene colour, 3 scene depth, 4 the
        // environment as the screen-space pass has it, 8 the shell's span, past the Renderer's units).
        const auto unit = [&](const char* name, int u) { glProgramUniform1i(raycast, find(name), u); };
        unit("u_atlas", 0);
        unit("u_bricks", 1);
        unit("u_scene_color", 2);
        unit("u_scene_depth", 3);
        unit("u_environment", 4);
        unit("u_span", kSpanUnit);
        glProgramUniform1f(raycast, find("u_step"), s.step);
        glProgramUniform1i(raycast, find("u_refine"), s.refine);
        glProgramUniform1f(raycast, find("u_thickness_step"), kThicknessStep);
        glProgramUniform1f(raycast, find("u_refraction"), kRefraction);
        glProgramUniform2f(raycast, find("u_near_far"), kCameraNear, kCameraFar);
        glProgramUniform2f(raycast, find("u_viewport"), static_cast<float>(w), static_cast<float>(h));
        glProgramUniform2f(shell, glGetUniformLocation(shell, "u_viewport"), static_cast<float>(w),
                           static_cast<float>(h));
        set_water(WaterLook{});
        set_environment(0, 0.0f);

        color_target = create_texture_2d(GL_RGBA8, w, h, GL_NEAREST);
        depth_target = create_texture_2d(GL_R32F, w, h, GL_NEAREST);
        thickness_target = create_texture_2d(GL_R32F, w, h, GL_NEAREST);
        span_target = create_texture_2d(GL_RG32F, w, h, GL_NEAREST);
        shell_depth = create_texture_2d(GL_DEPTH_COMPONENT24, w, h, GL_NEAREST);
        fbo = create_framebuffer({color_target, depth_target, thickness_target}, shell_depth, "VolumePass");
        span_fbo = create_framebuffer({span_target}, shell_depth, "VolumePass");
        scene_color = create_texture_2d(GL_RGBA8, w, h, GL_LINEAR);
        scene_depth = create_texture_2d(GL_DEPTH_COMPONENT24, w, h, GL_NEAREST);
        atlas = create_texture_3d(GL_LINEAR);
        bricks = create_texture_3d(GL_NEAREST);
        glGenVertexArrays(1, &empty_vao);
        shell_buffer.create();
        glGenVertexArrays(1, &shell_vao);
        glBindVertexArray(shell_vao);
        glBindVertexBuffer(0, shell_buffer.id, 0, sizeof(std::uint32_t));
        glVertexBindingDivisor(0, 1);
        glEnableVertexAttribArray(0);
        glVertexAttribIFormat(0, 1, GL_UNSIGNED_INT, 0);
        glVertexAttribBinding(0, 0);
        glBindVertexArray(0);
        glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max_3d_size);
        clear_targets({0, 0, w, h});
        check_gl("VolumePass setup");
    }

    ~Impl() {
        glDeleteProgram(shell);
        glDeleteProgram(raycast);
        const GLuint textures[] = {color_target, depth_target, thickness_target,
                                   span_target,  shell_depth,  scene_color,
                                   scene_depth,  atlas,        bricks};
        glDeleteTextures(9, textures);
        const GLuint fbos[] = {fbo, span_fbo};
        glDeleteFramebuffers(2, fbos);
        glDeleteBuffers(1, &shell_buffer.id);
        const GLuint vaos[] = {empty_vao, shell_vao};
        glDeleteVertexArrays(2, vaos);
    }

    void set_water(const WaterLook& w) {
        glProgramUniform3f(raycast, u_absorption, w.absorption.x, w.absorption.y, w.absorption.z);
        glProgramUniform3f(raycast, u_water_color, w.color.x, w.color.y, w.color.z);
        // The rays stop counting once no channel's transmission can change any more; a channel that
        // does not absorb never saturates, and the refraction's own cap (0.2) is the least that matters.
        float least = 0;
        for (float a : {w.absorption.x, w.absorption.y, w.absorption.z})
            if (a > 0 && (least == 0 || a < least)) least = a;
        const float cap = least > 0 ? std::max(0.2f, std::log(kSaturatedTransmission) / least) : 0.2f;
        glProgramUniform1f(raycast, u_thickness_cap, cap);
    }

    void set_environment(GLuint cube_map, float lod) {
        environment = cube_map;
        glProgramUniform1i(raycast, u_has_environment, cube_map != 0 ? 1 : 0);
        glProgramUniform1f(raycast, u_reflection_lod, lod);
    }

    void set_camera(const CameraDesc& c, Vec3f light) {
        const float aspect = static_cast<float>(width) / static_cast<float>(height);
        view_proj = view_projection(c, aspect);
        basis = camera_basis(c);
        const CameraBasis& b = basis;
        for (GLuint p : {shell, raycast}) {
            const CameraUniforms u(p);
            glProgramUniform3f(p, u.eye, b.eye.x, b.eye.y, b.eye.z);
            glProgramUniform3f(p, u.forward, b.forward.x, b.forward.y, b.forward.z);
            glProgramUniform3f(p, u.right, b.right.x, b.right.y, b.right.z);
            glProgramUniform3f(p, u.up, b.up.x, b.up.y, b.up.z);
            glProgramUniform2f(p, u.half_extent, b.tan_half_fov_y * aspect, b.tan_half_fov_y);
            glProgramUniformMatrix4fv(p, u.view_proj, 1, GL_FALSE, view_proj.data());
        }
        glProgramUniform3f(raycast, u_light, light.x, light.y, light.z);
    }

    // With time_passes: waits for GL and charges the time since the last mark to `slot`.
    void mark(double* slot) {
        if (!settings.time_passes) return;
        glFinish();
        const Clock::time_point now = Clock::now();
        if (slot) *slot = std::chrono::duration<double, std::milli>(now - mark_time).count();
        mark_time = now;
    }

    // --- upload ---

    // Everything the shader trusts: a slot outside the atlas would read another brick's samples, or
    // memory the upload never wrote.
    void check(const DensityVolumeView& v) const {
        const DensityGrid& g = v.grid;
        if (v.slot_max.size() != v.slot_min.size())
            bad_volume(fmt::format("{} least and {} greatest values for the stored bricks", v.slot_min.size(),
                                   v.slot_max.size()));
        if (!(g.voxel > 0 && std::isfinite(g.voxel)) || !std::isfinite(g.ox) || !std::isfinite(g.oy) ||
            !std::isfinite(g.oz))
            bad_volume(
                fmt::format("grid origin ({}, {}, {}) or voxel {} is not usable", g.ox, g.oy, g.oz, g.voxel));
        if (!(v.iso > 0 && std::isfinite(v.iso)))
            bad_volume(fmt::format("iso value {} is not positive (F = 0 outside the stored bricks)", v.iso));
        const auto max_dim = static_cast<std::uint32_t>(std::max(max_3d_size, 1));
        if (g.bx == 0 || g.by == 0 || g.bz == 0 || g.bx > max_dim || g.by > max_dim || g.bz > max_dim)
            bad_volume(
                fmt::format("grid of {}x{}x{} bricks (each axis in [1, {}])", g.bx, g.by, g.bz, max_dim));
        // Face instances carry the block index in 29 bits.
        if (std::uint64_t(g.bx) * g.by * g.bz * kBlocksPerBrick * kBlocksPerBrick * kBlocksPerBrick >=
            (std::uint64_t(1) << 29))
            bad_volume(fmt::format("grid of {}x{}x{} bricks is too large", g.bx, g.by, g.bz));
        if (v.slot_brick.size() != v.slot_min.size())
            bad_volume(fmt::format("{} bricks named for {} stored", v.slot_brick.size(), v.slot_min.size()));
        if (v.brick_slot.size() != std::size_t(g.bricks()))
            bad_volume(
                fmt::format("{} brick slots for a grid of {} bricks", v.brick_slot.size(), g.bricks()));
        const std::uint32_t layers = atlas_layers(v.stored());
        if (v.atlas.size() < atlas_samples(layers))
            bad_volume(fmt::format("atlas of {} samples for {} stored bricks (needs {})", v.atlas.size(),
                                   v.stored(), atlas_samples(layers)));
        if (std::size_t(layers) * kBrickEdge > std::size_t(max_3d_size))
            throw std::runtime_error(
                fmt::format("VolumePass: {} stored bricks need an atlas {} samples deep; GL "
                            "allows {}",
                            v.stored(), std::size_t(layers) * kBrickEdge, max_3d_size));
    }

    void ensure_atlas(std::uint32_t layers) {
        if (layers <= atlas_layer_capacity) return;
        glBindTexture(GL_TEXTURE_3D, atlas);
        glTexImage3D(GL_TEXTURE_3D, 0, GL_R32F, kAtlasEdge, kAtlasEdge,
                     static_cast<GLsizei>(layers * kBrickEdge), 0, GL_RED, GL_FLOAT, nullptr);
        check_gl(fmt::format("VolumePass: an atlas of {} layers ({} MiB)", layers,
                             atlas_samples(layers) * sizeof(float) >> 20));
        atlas_layer_capacity = layers;
        glProgramUniform3f(raycast, u_atlas_scale, 1.0f / float(kAtlasEdge), 1.0f / float(kAtlasEdge),
                           1.0f / float(layers * kBrickEdge));
    }

    void ensure_bricks(const DensityGrid& g) {
        std::array<std::uint32_t, 3>& c = brick_capacity;
        if (g.bx <= c[0] && g.by <= c[1] && g.bz <= c[2]) return;
        c = {std::max(c[0], g.bx), std::max(c[1], g.by), std::max(c[2], g.bz)};
        glBindTexture(GL_TEXTURE_3D, bricks);
        glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA32F, static_cast<GLsizei>(c[0]), static_cast<GLsizei>(c[1]),
                     static_cast<GLsizei>(c[2]), 0, GL_RGBA, GL_FLOAT, nullptr);
        check_gl("VolumePass: the brick table");
    }

    // The faces between a block a ray can find the surface in and one it cannot, or the grid's end: what
    // the shell pass draws. A block can hold the surface only if some sample of it reaches the iso value
    // (a trilinear field never exceeds its corners), so whole bricks decide first and only the bricks
    // the surface crosses are read sample by sample.
    void find_shell(const DensityVolumeView& v) {
        const DensityGrid& g = v.grid;
        const std::uint32_t nx = g.bx * kBlocksPerBrick, ny = g.by * kBlocksPerBrick,
                            nz = g.bz * kBlocksPerBrick;
        block_occupied.assign(std::size_t(nx) * ny * nz, 0);
        occupied_blocks.clear();
        const auto block_index = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
            return (std::size_t(k) * ny + j) * nx + i;
        };
        for (std::uint32_t slot = 0; slot < v.stored(); ++slot) {
            if (v.slot_max[slot] < v.iso) continue;
            const std::uint32_t brick = v.slot_brick[slot];
            if (brick >= g.bricks() || v.brick_slot[brick] != static_cast<std::int32_t>(slot))
                bad_volume(fmt::format("slot {} names brick {}, whose slot is not {}", slot, brick, slot));
            const std::uint32_t a = brick % g.bx, b = (brick / g.bx) % g.by, c = brick / (g.bx * g.by);
            const bool solid = v.slot_min[slot] >= v.iso;
            const float* samples = v.atlas.data() + atlas_offset(slot, 0, 0, 0);
            for (std::uint32_t k = 0; k < kBlocksPerBrick; ++k)
                for (std::uint32_t j = 0; j < kBlocksPerBrick; ++j)
                    for (std::uint32_t i = 0; i < kBlocksPerBrick; ++i) {
                        bool reaches = solid;
                        for (std::uint32_t z = 0; z <= kBlockCells && !reaches; ++z)
                            for (std::uint32_t y = 0; y <= kBlockCells && !reaches; ++y) {
                                const float* row =
                                    samples +
                                    (std::size_t(k * kBlockCells + z) * kAtlasEdge + j * kBlockCells + y) *
                                        kAtlasEdge +
                                    i * kBlockCells;
                                for (std::uint32_t x = 0; x <= kBlockCells; ++x)
                                    reaches = reaches || row[x] >= v.iso;
                            }
                        if (!reaches) continue;
                        const std::size_t index = block_index(
                            a * kBlocksPerBrick + i, b * kBlocksPerBrick + j, c * kBlocksPerBrick + k);
                        block_occupied[index] = 1;
                        occupied_blocks.push_back(static_cast<std::uint32_t>(index));
                    }
        }
        shell_faces.clear();
        for (const std::uint32_t index : occupied_blocks) {
            const std::uint32_t i = index % nx, j = (index / nx) % ny, k = index / (nx * ny);
            const auto empty = [&](std::uint32_t x, std::uint32_t y, std::uint32_t z) {
                return block_occupied[block_index(x, y, z)] == 0;
            };
            const std::uint32_t face = index << 3;
            if (i == 0 || empty(i - 1, j, k)) shell_faces.push_back(face | kMinusX);
            if (i + 1 == nx || empty(i + 1, j, k)) shell_faces.push_back(face | kPlusX);
            if (j == 0 || empty(i, j - 1, k)) shell_faces.push_back(face | kMinusY);
            if (j + 1 == ny || empty(i, j + 1, k)) shell_faces.push_back(face | kPlusY);
            if (k == 0 || empty(i, j, k - 1)) shell_faces.push_back(face | kMinusZ);
            if (k + 1 == nz || empty(i, j, k + 1)) shell_faces.push_back(face | kPlusZ);
        }
        shell_buffer.upload(shell_faces.data(), shell_faces.size() * sizeof(std::uint32_t));
    }

    void upload(const DensityVolumeView& v) {
        timings = {};
        mark(nullptr);
        stored = 0;
        if (v.stored() == 0) return;
        check(v);
        const DensityGrid& g = v.grid;

        // Per brick: its slot, least and greatest sample; bricks not stored hold F = 0, below any iso.
        brick_table.resize(std::size_t(g.bricks()) * 4);
        const auto n = static_cast<std::int64_t>(v.stored());
        for (std::size_t b = 0; b < v.brick_slot.size(); ++b) {
            const std::int32_t s = v.brick_slot[b];
            float* e = &brick_table[4 * b];
            if (s < 0) {
                e[0] = -1, e[1] = 0, e[2] = 0, e[3] = 0;
                continue;
            }
            if (s >= n) bad_volume(fmt::format("brick {} names slot {} of {} stored", b, s, n));
            const auto slot = static_cast<std::size_t>(s);
            e[0] = static_cast<float>(s), e[1] = v.slot_min[slot], e[2] = v.slot_max[slot], e[3] = 0;
        }
        find_shell(v);

        const std::uint32_t layers = atlas_layers(v.stored());
        ensure_atlas(layers);
        ensure_bricks(g);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        glBindTexture(GL_TEXTURE_3D, atlas);
        // Whole layers in one call; of the last, partly used layer only the rows of bricks in use.
        const std::uint32_t full = v.stored() / kAtlasLayerBricks, rest = v.stored() % kAtlasLayerBricks;
        if (full > 0)
            glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, kAtlasEdge, kAtlasEdge,
                            static_cast<GLsizei>(full * kBrickEdge), GL_RED, GL_FLOAT, v.atlas.data());
        if (rest > 0) {
            const std::uint32_t rows = (rest + kAtlasBricks - 1) / kAtlasBricks * kBrickEdge;
            glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, kAtlasEdge);
            glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, static_cast<GLint>(full * kBrickEdge), kAtlasEdge,
                            static_cast<GLsizei>(rows), kBrickEdge, GL_RED, GL_FLOAT,
                            v.atlas.data() + atlas_samples(full));
            glPixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
        }
        glBindTexture(GL_TEXTURE_3D, bricks);
        glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, static_cast<GLsizei>(g.bx), static_cast<GLsizei>(g.by),
                        static_cast<GLsizei>(g.bz), GL_RGBA, GL_FLOAT, brick_table.data());
        glBindTexture(GL_TEXTURE_3D, 0);

        grid = g;
        stored = v.stored();
        const auto gx = static_cast<GLint>(g.bx), gy = static_cast<GLint>(g.by),
                   gz = static_cast<GLint>(g.bz);
        glProgramUniform3f(raycast, u_origin, g.ox, g.oy, g.oz);
        glProgramUniform1f(raycast, u_voxel, g.voxel);
        glProgramUniform3i(raycast, u_grid, gx, gy, gz);
        glProgramUniform1i(raycast, u_max_bricks, gx + gy + gz);
        glProgramUniform1f(raycast, u_iso, v.iso);
        glProgramUniform3f(shell, shell_origin, g.ox, g.oy, g.oz);
        glProgramUniform1f(shell, shell_block, g.voxel * float(kBlockCells));
        const auto blocks = static_cast<GLint>(kBlocksPerBrick);
        glProgramUniform3i(shell, shell_blocks, gx * blocks, gy * blocks, gz * blocks);
        mark(&timings.upload);
    }

    // --- draw ---

    Rect clamped(float x0, float y0, float x1, float y1) const {
        const auto cx = [&](float x) { return static_cast<int>(std::clamp(x, 0.0f, float(width))); };
        const auto cy = [&](float y) { return static_cast<int>(std::clamp(y, 0.0f, float(height))); };
        return {cx(std::floor(x0)), cy(std::floor(y0)), cx(std::ceil(x1)), cy(std::ceil(y1))};
    }

    // Where rays may find water (the grid's box, clipped) and the pixels that can see it. `whole_box`:
    // the eye is inside or beside the grid, or part of it lies behind the near plane, where the shell's
    // faces (from the whole grid) would be cut by the near plane and lose the pixels whose rays start
    // inside the water; the rays walk the whole box there instead.
    struct Coverage {
        Vec3f lo, hi;  // world
        Rect pixels;
        bool whole_box = false;
    };

    // The pixel box around the projections of the corners of lo..hi; false when a corner lies behind
    // the near plane.
    bool project_box(Vec3f lo, Vec3f hi, Rect& out) const {
        const float hw = 0.5f * float(width), hh = 0.5f * float(height);
        float x0 = 1e30f, y0 = 1e30f, x1 = -1e30f, y1 = -1e30f;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3f p{corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y, corner & 4 ? hi.z : lo.z};
            const Eigen::Vector4f clip = clip_of(view_proj, p);
            const float cx = clip.x(), cy = clip.y(), cw = clip.w();
            if (cw < kCameraNear) return false;
            x0 = std::min(x0, (cx / cw + 1) * hw), x1 = std::max(x1, (cx / cw + 1) * hw);
            y0 = std::min(y0, (cy / cw + 1) * hh), y1 = std::max(y1, (cy / cw + 1) * hh);
        }
        out = clamped(x0 - 1, y0 - 1, x1 + 1, y1 + 1);
        return true;
    }

    Coverage coverage() const {
        Coverage c;
        const Vec3f lo{grid.ox, grid.oy, grid.oz};
        const Vec3f hi =
            lo + Vec3f{float(grid.bx), float(grid.by), float(grid.bz)} * (grid.voxel * float(kBrickCells));
        c.lo = {std::max(lo.x, clip_lo.x), std::max(lo.y, clip_lo.y), std::max(lo.z, clip_lo.z)};
        c.hi = {std::min(hi.x, clip_hi.x), std::min(hi.y, clip_hi.y), std::min(hi.z, clip_hi.z)};
        if (!(c.lo.x < c.hi.x && c.lo.y < c.hi.y && c.lo.z < c.hi.z)) return c;  // nothing to draw
        const Vec3f e = basis.eye;
        const Vec3f nearest{std::clamp(e.x, lo.x, hi.x), std::clamp(e.y, lo.y, hi.y),
                            std::clamp(e.z, lo.z, hi.z)};
        Rect whole;
        c.whole_box = length(nearest - e) < 2 * kCameraNear || !project_box(lo, hi, whole);
        if (c.whole_box || !project_box(c.lo, c.hi, c.pixels)) c.pixels = Rect{0, 0, width, height};
        return c;
    }

    void scissor(Rect r) { glScissor(r.x0, r.y0, r.x1 - r.x0, r.y1 - r.y0); }

    // Depth and thickness to zero within `r`: no water.
    void clear_targets(Rect r) {
        if (r.empty()) return;
        const GLfloat zero[4] = {0, 0, 0, 0};
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glEnable(GL_SCISSOR_TEST);
        scissor(r);
        glClearBufferfv(GL_COLOR, 1, zero);
        glClearBufferfv(GL_COLOR, 2, zero);
        glDisable(GL_SCISSOR_TEST);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
    }

    // The scene behind, colour and depth as far as refraction can reach from where rays run (the depth
    // tells a refracted lookup what stands in front of the water), and the picture the rays draw the
    // water into.
    void copy_scene(Rect r) {
        const float mx = kRefractionReach * float(width) + 2, my = kRefractionReach * float(height) + 2;
        const Rect wide = clamped(float(r.x0) - mx, float(r.y0) - my, float(r.x1) + mx, float(r.y1) + my);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, scene_color);
        glCopyTexSubImage2D(GL_TEXTURE_2D, 0, wide.x0, wide.y0, wide.x0, wide.y0, wide.x1 - wide.x0,
                            wide.y1 - wide.y0);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, scene_depth);
        glCopyTexSubImage2D(GL_TEXTURE_2D, 0, wide.x0, wide.y0, wide.x0, wide.y0, wide.x1 - wide.x0,
                            wide.y1 - wide.y0);
        // The picture's copy from the scene copy, not from the framebuffer again: a plain memory copy.
        glCopyImageSubData(scene_color, GL_TEXTURE_2D, 0, r.x0, r.y0, 0, color_target, GL_TEXTURE_2D, 0, r.x0,
                           r.y0, 0, r.x1 - r.x0, r.y1 - r.y0, 1);
        glActiveTexture(GL_TEXTURE0);
    }

    // The span each pixel's ray walks, and the depth buffer marking the pixels with one. Without the
    // shell (whole_box) every pixel of `r` is marked and rays walk the whole box.
    void draw_shell(Rect r, bool whole_box) {
        glBindFramebuffer(GL_FRAMEBUFFER, span_fbo);
        scissor(r);
        glClearDepth(whole_box ? 0.0 : 1.0);
        glClear(GL_DEPTH_BUFFER_BIT);
        glClearDepth(1.0);
        if (whole_box || shell_faces.empty()) return;
        const GLfloat nothing[4] = {-3.0e38f, 0, 0, 0};
        glClearBufferfv(GL_COLOR, 0, nothing);
        // Every face: the nearest entry and the farthest exit come from blending, not the depth test.
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_ALWAYS);
        glDepthMask(GL_TRUE);
        glEnable(GL_BLEND);
        glBlendEquation(GL_MAX);
        glBlendFunc(GL_ONE, GL_ONE);
        glEnable(GL_DEPTH_CLAMP);  // every corner lies in front of the near plane (coverage())
        glUseProgram(shell);
        glBindVertexArray(shell_vao);
        glDrawArraysInstanced(GL_TRIANGLES, 0, 6, static_cast<GLsizei>(shell_faces.size()));
        glDisable(GL_DEPTH_CLAMP);
        glBlendEquation(GL_FUNC_ADD);
        glDisable(GL_BLEND);
    }

    void draw() {
        mark(nullptr);
        const Coverage c = stored > 0 ? coverage() : Coverage{};
        clear_targets(united(dirty, c.pixels));
        dirty = c.pixels;
        if (c.pixels.empty()) {
            mark(&timings.raycast);
            return;
        }
        copy_scene(c.pixels);
        const float inv = 1.0f / grid.voxel;
        const Vec3f origin{grid.ox, grid.oy, grid.oz}, lo = (c.lo - origin) * inv, hi = (c.hi - origin) * inv;
        glProgramUniform3f(raycast, u_ray_lo, lo.x, lo.y, lo.z);
        glProgramUniform3f(raycast, u_ray_hi, hi.x, hi.y, hi.z);
        glProgramUniform1i(raycast, u_use_span, c.whole_box ? 0 : 1);

        glViewport(0, 0, width, height);
        glEnable(GL_SCISSOR_TEST);
        draw_shell(c.pixels, c.whole_box);

        // The rays, at the far plane against the shell's depth: llvmpipe skips the shader for blocks of
        // pixels the test rejects whole, while a branch in the shader would still run both sides.
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        scissor(c.pixels);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_GREATER);
        glDepthMask(GL_FALSE);
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_3D, atlas);
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_3D, bricks);
        glActiveTexture(GL_TEXTURE0 + kSpanUnit);
        glBindTexture(GL_TEXTURE_2D, span_target);
        if (environment != 0) {  // else the analytic sky; leave the Renderer's unit as it is
            glActiveTexture(GL_TEXTURE4);
            glBindTexture(GL_TEXTURE_CUBE_MAP, environment);
        }
        glUseProgram(raycast);
        glBindVertexArray(empty_vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);

        // The water into the picture. Like the screen-space composite it leaves the scene's depth as it
        // is: what comes after (the tank's front glass) lies in front of the water.
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
        const Rect& r = c.pixels;
        glBlitFramebuffer(r.x0, r.y0, r.x1, r.y1, r.x0, r.y0, r.x1, r.y1, GL_COLOR_BUFFER_BIT, GL_NEAREST);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDisable(GL_SCISSOR_TEST);
        glActiveTexture(GL_TEXTURE0);
        glBindVertexArray(0);
        mark(&timings.raycast);
    }

    void read(VolumeBuffer which, std::span<float> out) const {
        if (out.size() < std::size_t(width) * std::size_t(height))
            throw std::invalid_argument("VolumePass::read: buffer too small");
        glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
        glReadBuffer(which == VolumeBuffer::kDepth ? GL_COLOR_ATTACHMENT1 : GL_COLOR_ATTACHMENT2);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, width, height, GL_RED, GL_FLOAT, out.data());
        glReadBuffer(GL_COLOR_ATTACHMENT0);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    }
};

VolumePass::VolumePass(int width, int height, const VolumeRaycastSettings& settings)
    : impl_(std::make_unique<Impl>(width, height, settings)) {}
VolumePass::~VolumePass() = default;

void VolumePass::set_camera(const CameraDesc& camera, Vec3f light_dir) {
    impl_->set_camera(camera, light_dir);
}
void VolumePass::set_water(const WaterLook& water) {
    impl_->set_water(water);
}
void VolumePass::set_environment(unsigned cube_map_texture, float reflection_lod) {
    impl_->set_environment(cube_map_texture, reflection_lod);
}
void VolumePass::set_clip(Vec3f lo, Vec3f hi) {
    impl_->clip_lo = lo, impl_->clip_hi = hi;
}
void VolumePass::clear_clip() {
    impl_->clip_lo = {-kNoClip, -kNoClip, -kNoClip}, impl_->clip_hi = {kNoClip, kNoClip, kNoClip};
}
void VolumePass::render(const DensityVolumeView& volume) {
    impl_->upload(volume);
    impl_->draw();
}
void VolumePass::upload(const DensityVolumeView& volume) {
    impl_->upload(volume);
}
void VolumePass::draw() {
    impl_->draw();
}
void VolumePass::read(VolumeBuffer which, std::span<float> out) const {
    impl_->read(which, out);
}
const VolumeTimings& VolumePass::timings() const {
    return impl_->timings;
}

}  // namespace rivulet
