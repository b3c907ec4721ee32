#include "systems/render/renderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "jobs/low_res_sphere.h"
#include "systems/render/camera.h"
#include "systems/render/environment_map.h"
#include "systems/render/gl.h"
#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/osmesa_context.h"
#include "systems/render/render_programs.h"
#include "systems/render/scene_geometry.h"
#include "systems/render/shaders.h"
#include "systems/render/shadow_map.h"
#include "systems/render/sprite_pass.h"
#include "systems/render/water_backdrop.h"

namespace rivulet {
namespace {

constexpr int kMinSize = 16, kMaxSize = 8192;
constexpr std::size_t kVertexBytes = 6 * sizeof(float);
// u_clip while nothing is clipped: llvmpipe applies the clip distances a shader writes even with
// GL_CLIP_DISTANCEi disabled.
constexpr float kNoClip = 1e30f;

int checked_size(int value, const char* what) {
    if (value < kMinSize || value > kMaxSize) {
        throw std::runtime_error(std::string("Renderer: picture ") + what + " " + std::to_string(value) +
                                 " is outside [" + std::to_string(kMinSize) + ", " +
                                 std::to_string(kMaxSize) + "]");
    }
    return value;
}

const void* index_byte_offset(std::size_t index) {
    return reinterpret_cast<const void*>(index * sizeof(std::uint32_t));
}

[[noreturn]] void bad_frame(const std::string& what) {
    throw std::out_of_range("Renderer::render: " + what);
}

}  // namespace

struct Renderer::Impl {
    OsMesaContext context;
    LitPrograms lit;
    SkyProgram sky;
    ShadowProgram shadow;
    ShadowPointProgram shadow_points;
    ThicknessProgram thickness;
    ThicknessPointProgram thickness_points;
    ShadowMap shadow_map;
    WaterBackdrop backdrop;
    ShadowFit shadow_fit;
    float max_point_size = 1;
    EnvironmentMap environment;
    GLuint empty_vao = 0;  // the sky draws from gl_VertexID, but core profile still wants a VAO bound

    GLuint static_vbo = 0, static_ibo = 0, static_vao = 0;
    IndexRange ground, ground_far, solids, tank_frame, glass_back, glass_front;
    Vec3f tank_offset;
    std::vector<IndexRange> movers;
    std::array<Vec3f, kMaxMovers> mover_offsets{};
    // SPH scenes: the fluid is clipped to the tank's glass box (at tank_offset). Surfaces reach past the
    // particles (scan conversion's round cylinders most of all), and a tank drawn around them must not
    // show water outside its walls.
    bool clip_fluid = false;
    BoxCollider glass_box;

    CylinderLayout layout;
    std::uint32_t max_cylinders = 0;
    GLuint cylinder_vbo = 0, cylinder_ibo = 0, cylinder_vao = 0;
    // Multi-draw arguments, three draws per group; they only grow, so steady frames do not allocate.
    std::vector<GLsizei> draw_counts;
    std::vector<const void*> draw_offsets;
    std::vector<GLint> draw_base_vertices;

    GrowingBuffer mesh_vbo, mesh_ibo;
    GLuint mesh_vao = 0;

    GLuint sphere_vbo = 0, sphere_ibo = 0, sphere_vao = 0;
    GrowingBuffer sphere_instances;
    GLsizei sphere_index_count = 0;

    // The screen-space fluid's particles once more, for their shadows (its own copies are private).
    GrowingBuffer sprite_x, sprite_y, sprite_z;
    GLuint sprite_vao = 0;
    // The isolated spheres' centres (sphere_instances) as points, for their shadows.
    GLuint sphere_point_vao = 0;

    std::unique_ptr<ScreenFluidPass> screen;
    std::unique_ptr<SpritePass> diffuse;
    std::unique_ptr<VolumePass> volume;
    CameraDesc camera_desc;  // of the scene, for passes set up after it
    WaterLook water;
    Vec3f light{0, 1, 0};
    // The pool's water is a height field with no bottom: the lit water absorbs over this depth instead.
    float pool_depth = 0;

    GLuint pool_vbo = 0, pool_ibo = 0, pool_vao = 0;
    int pool_nx = 0, pool_nz = 0;
    GLsizei pool_index_count = 0;
    std::vector<float> pool_vertices;

    bool time_passes = false;
    RenderTimings timings;
    std::chrono::steady_clock::time_point mark_time;

    // What this frame uploaded, drawn by both the shadow and the main pass.
    struct Uploaded {
        bool pool = false;
        GLsizei cylinder_draws = 0, mesh_indices = 0, spheres = 0, sprites = 0;
        bool mesh_casts_shadow = true;
        float radius = 0;
    } up;

    Impl(int width, int height)
        : context(checked_size(width, "width"), checked_size(height, "height")),
          lit(build_lit_programs()),
          sky(build_sky_program()),
          shadow(build_shadow_program()),
          shadow_points(build_shadow_point_program()),
          thickness(build_thickness_program()),
          thickness_points(build_thickness_point_program()),
          shadow_map(kShadowMapSize),
          backdrop(width, height) {
        for (const LitProgram& p : lit) {
            glProgramUniform1f(p.id, p.scale, 1.0f);
            glProgramUniform4f(p.id, p.clip, -kNoClip, -kNoClip, kNoClip, kNoClip);
            glProgramUniform2f(p.id, p.viewport, static_cast<float>(width), static_cast<float>(height));
            glProgramUniform1f(p.id, p.refraction, shaders::kRefraction);
        }
        // The thickness is taken of the whole closed surface, never clipped (draw_thickness).
        glProgramUniform4f(thickness.id, thickness.clip, -kNoClip, -kNoClip, kNoClip, kNoClip);
        glProgramUniform4f(shadow.id, shadow.clip, -kNoClip, -kNoClip, kNoClip, kNoClip);
        glGenVertexArrays(1, &empty_vao);
        create_static_objects();
        create_sphere_objects();
        create_sprite_objects();
        mesh_vbo.create();
        mesh_ibo.create();
        mesh_vao = create_mesh_vao(mesh_vbo.id, mesh_ibo.id);
        cylinder_vbo = create_buffer();
        cylinder_ibo = create_buffer();
        cylinder_vao = create_mesh_vao(cylinder_vbo, cylinder_ibo);
        pool_vbo = create_buffer();
        pool_ibo = create_buffer();
        pool_vao = create_mesh_vao(pool_vbo, pool_ibo);
        float point_sizes[2] = {1, 1};
        glGetFloatv(GL_POINT_SIZE_RANGE, point_sizes);
        max_point_size = point_sizes[1];
        glProgramUniform1f(thickness_points.id, thickness_points.max_point_size, max_point_size);
        glProgramUniform2f(thickness_points.id, thickness_points.viewport, float(backdrop.thickness_width()),
                           float(backdrop.thickness_height()));
        glViewport(0, 0, width, height);
        glDisable(GL_CULL_FACE);
        glDepthFunc(GL_LESS);
        glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
        // Until set_scene: the default camera's sky and an empty stage.
        apply_camera(CameraDesc{});
        environment.make_sky(light);
        set_environment();
        fit_shadows(SceneDesc{});
        set_water(WaterLook{});
        check_gl("renderer setup");
    }

    ~Impl() { context.make_current(); }  // members below delete their GL objects in this context

    void create_static_objects() {
        static_vbo = create_buffer();
        static_ibo = create_buffer();
        static_vao = create_mesh_vao(static_vbo, static_ibo);
    }

    void create_sphere_objects() {
        const SphereTemplate& s = low_res_sphere();
        sphere_vbo = create_buffer();
        sphere_ibo = create_buffer();
        buffer_data(sphere_vbo, s.positions.size() * sizeof(float), s.positions.data(), GL_STATIC_DRAW);
        buffer_data(sphere_ibo, s.indices.size() * sizeof(std::uint32_t), s.indices.data(), GL_STATIC_DRAW);
        sphere_index_count = static_cast<GLsizei>(s.indices.size());
        sphere_instances.create();
        sphere_vao = create_instanced_sphere_vao(sphere_vbo, sphere_ibo, sphere_instances.id);
    }

    // Points for the shadow pass, one float per attribute (kShadowPointVertex): x, y and z from three
    // buffers (the particles' arrays as they are) or from one interleaved buffer (the sphere centres).
    static GLuint point_vao(const GLuint (&buffers)[3], GLsizei stride, const GLuint (&offsets)[3]) {
        GLuint vao = 0;
        glGenVertexArrays(1, &vao);
        glBindVertexArray(vao);
        for (GLuint a = 0; a < 3; ++a) {
            glBindVertexBuffer(a, buffers[a], 0, stride);
            glEnableVertexAttribArray(a);
            glVertexAttribFormat(a, 1, GL_FLOAT, GL_FALSE, offsets[a]);
            glVertexAttribBinding(a, a);
        }
        glBindVertexArray(0);
        return vao;
    }

    void create_sprite_objects() {
        sprite_x.create(), sprite_y.create(), sprite_z.create();
        sprite_vao = point_vao({sprite_x.id, sprite_y.id, sprite_z.id}, sizeof(float), {0, 0, 0});
        const GLuint centres = sphere_instances.id;
        sphere_point_vao = point_vao({centres, centres, centres}, 3 * sizeof(float), {0, 4, 8});
    }

    void apply_camera(const CameraDesc& camera) {
        const float aspect = static_cast<float>(context.width()) / static_cast<float>(context.height());
        const Mat4 vp = view_projection(camera, aspect);
        const CameraBasis b = camera_basis(camera);
        light = key_light(camera);
        camera_desc = camera;
        if (screen) screen->set_camera(camera, light);
        if (volume) volume->set_camera(camera, light);
        if (diffuse) diffuse->set_camera(camera);
        for (const LitProgram& p : lit) {
            glProgramUniformMatrix4fv(p.id, p.view_proj, 1, GL_FALSE, vp.data());
            glProgramUniform3f(p.id, p.eye, b.eye.x, b.eye.y, b.eye.z);
            glProgramUniform3f(p.id, p.light_dir, light.x, light.y, light.z);
            glProgramUniform3f(p.id, p.right, b.right.x, b.right.y, b.right.z);
            glProgramUniform3f(p.id, p.up, b.up.x, b.up.y, b.up.z);
        }
        glProgramUniformMatrix4fv(thickness.id, thickness.view_proj, 1, GL_FALSE, vp.data());
        glProgramUniform3f(thickness.id, thickness.eye, b.eye.x, b.eye.y, b.eye.z);
        const ThicknessPointProgram& tp = thickness_points;
        glProgramUniformMatrix4fv(tp.id, tp.view_proj, 1, GL_FALSE, vp.data());
        glProgramUniform3f(tp.id, tp.eye, b.eye.x, b.eye.y, b.eye.z);
        glProgramUniform3f(tp.id, tp.forward, b.forward.x, b.forward.y, b.forward.z);
        glProgramUniform3f(tp.id, tp.right, b.right.x, b.right.y, b.right.z);
        glProgramUniform3f(tp.id, tp.up, b.up.x, b.up.y, b.up.z);
        glProgramUniform2f(tp.id, tp.half_extent, b.tan_half_fov_y * aspect, b.tan_half_fov_y);
        glProgramUniform1f(tp.id, tp.pixels_per_unit,
                           0.5f * float(backdrop.thickness_height()) / b.tan_half_fov_y);
        glProgramUniform3f(sky.id, sky.forward, b.forward.x, b.forward.y, b.forward.z);
        glProgramUniform3f(sky.id, sky.right, b.right.x, b.right.y, b.right.z);
        glProgramUniform3f(sky.id, sky.up, b.up.x, b.up.y, b.up.z);
        glProgramUniform2f(sky.id, sky.half_extent, b.tan_half_fov_y * aspect, b.tan_half_fov_y);
    }

    // The light's box around the scene's stage; it depends on the scene only, so it is fitted once.
    void fit_shadows(const SceneDesc& scene) {
        shadow_fit = fit_shadow(light, shadow_stage(scene), shadow_map.resolution(), scene.ground_y);
        for (const LitProgram& p : lit) {
            glProgramUniformMatrix4fv(p.id, p.shadow_matrix, 1, GL_FALSE, shadow_fit.texture_matrix.data());
            glProgramUniform1f(p.id, p.shadow_texel, shadow_fit.texel_world);
        }
        glProgramUniformMatrix4fv(shadow.id, shadow.light_view_proj, 1, GL_FALSE,
                                  shadow_fit.light_view_proj.data());
        glProgramUniformMatrix4fv(shadow_points.id, shadow_points.light_view_proj, 1, GL_FALSE,
                                  shadow_fit.light_view_proj.data());
    }

    void set_environment() {
        const Vec3f h = environment.horizon_color();
        const float lod = reflection_lod();
        for (const LitProgram& p : lit) {
            glProgramUniform3f(p.id, p.horizon, h.x, h.y, h.z);
            glProgramUniform1f(p.id, p.reflection_lod, lod);
        }
        if (screen) screen->set_environment(environment.texture());
        if (volume) volume->set_environment(environment.texture(), lod);
    }

    // The level the lit water's reflections read (kLitFragment's u_reflection_lod).
    float reflection_lod() const {
        return std::max(0.0f, std::log2(static_cast<float>(environment.face_size()) / kSkyFaceSize));
    }

    void set_water(const WaterLook& w) {
        water = w;
        for (int variant : {shaders::kLitWater, shaders::kLitPool}) {
            const LitProgram& p = lit[std::size_t(variant)];
            glProgramUniform3f(p.id, p.water_color, w.color.x, w.color.y, w.color.z);
            glProgramUniform3f(p.id, p.absorption, w.absorption.x, w.absorption.y, w.absorption.z);
        }
        if (screen) screen->set_water(w);
        if (volume) volume->set_water(w);
    }

    void set_scene(const SceneDesc& scene) {
        context.make_current();
        apply_camera(scene.camera);
        if (scene.look.environment.faces.empty()) {
            environment.make_sky(light);
        } else {
            environment.load_faces(scene.look.environment.faces);
        }
        set_environment();
        set_water(scene.look.water);
        fit_shadows(scene);
        const StaticGeometry g = build_static_geometry(scene, shadow_fit.ground);
        buffer_data(static_vbo, g.vertices.size() * sizeof(float), g.vertices.data(), GL_STATIC_DRAW);
        buffer_data(static_ibo, g.indices.size() * sizeof(std::uint32_t), g.indices.data(), GL_STATIC_DRAW);
        ground = g.ground, ground_far = g.ground_far, solids = g.solids, tank_frame = g.tank_frame;
        movers = g.movers;
        movers.resize(std::min(movers.size(), mover_offsets.size()));
        glass_back = g.glass_back, glass_front = g.glass_front;
        tank_offset = {};
        clip_fluid = scene.simulation == SimulationKind::kSph;
        if (clip_fluid) glass_box = tank_glass_box(scene);
        if (scene.pool.enabled) ensure_pool(scene.pool.nx, scene.pool.nz);
        // A pool at ground level still shows some body: its surface dips and the eye wants water there.
        pool_depth = std::max(scene.pool.level - scene.ground_y, 0.1f);
        check_gl("Renderer::set_scene");
    }

    // Allocates the pool grid's buffers; frames reuse them while the grid size stays the same.
    void ensure_pool(int nx, int nz) {
        if (nx == pool_nx && nz == pool_nz) return;
        if (nx < 2 || nz < 2) {
            throw std::runtime_error("Renderer: pool grid " + std::to_string(nx) + "x" + std::to_string(nz) +
                                     " needs at least 2x2 samples");
        }
        std::vector<std::uint32_t> indices(std::size_t(nx - 1) * std::size_t(nz - 1) * 6u);
        write_grid_indices(nx, nz, indices);
        buffer_data(pool_ibo, indices.size() * sizeof(std::uint32_t), indices.data(), GL_STATIC_DRAW);
        pool_vertices.assign(std::size_t(nx) * std::size_t(nz) * 6u, 0.0f);
        buffer_data(pool_vbo, pool_vertices.size() * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
        pool_nx = nx;
        pool_nz = nz;
        pool_index_count = static_cast<GLsizei>(indices.size());
    }

    void set_cylinder_pool(const CylinderLayout& l, std::uint32_t max) {
        context.make_current();
        if (l.u < 3 || l.v < 2 || max == 0) {
            throw std::runtime_error(
                "Renderer::set_cylinder_pool: needs u >= 3, v >= 2 and at least one cylinder");
        }
        const std::size_t bytes = std::size_t(max) * l.verts_per_cylinder() * kVertexBytes;
        if (std::size_t(max) * l.verts_per_cylinder() > std::size_t(INT32_MAX)) {
            throw std::runtime_error("Renderer::set_cylinder_pool: " + std::to_string(max) +
                                     " cylinders exceed the GL base-vertex range");
        }
        std::vector<std::uint32_t> indices(l.index_count());
        write_cylinder_indices(l, indices);
        buffer_data(cylinder_ibo, indices.size() * sizeof(std::uint32_t), indices.data(), GL_STATIC_DRAW);
        buffer_data(cylinder_vbo, bytes, nullptr, GL_DYNAMIC_DRAW);
        check_gl("Renderer::set_cylinder_pool (" + std::to_string(bytes >> 20) + " MiB vertex buffer)");
        layout = l;
        max_cylinders = max;
        const std::size_t draws = 3u * std::size_t(max);
        draw_counts.resize(draws);
        draw_offsets.resize(draws);
        draw_base_vertices.resize(draws);
    }

    void set_screen_fluid(const ScreenFluidSettings& settings) {
        context.make_current();
        screen = std::make_unique<ScreenFluidPass>(context.width(), context.height(), settings);
        screen->set_camera(camera_desc, light);
        screen->set_water(water);
        screen->set_environment(environment.texture());
    }

    void set_volume_raycast(const VolumeRaycastSettings& settings) {
        context.make_current();
        volume.reset();  // its textures go before the new ones are made
        volume = std::make_unique<VolumePass>(context.width(), context.height(), settings);
        volume->set_camera(camera_desc, light);
        volume->set_water(water);
        volume->set_environment(environment.texture(), reflection_lod());
    }

    void set_diffuse_sprites(std::uint32_t max_sprites) {
        if (diffuse && diffuse->max_sprites() == max_sprites) return;
        context.make_current();
        diffuse.reset();  // its buffer goes before the new one is made
        diffuse = std::make_unique<SpritePass>(max_sprites, context.width(), context.height());
        diffuse->set_camera(camera_desc);
    }

    // --- this frame's data into GL buffers, once for both passes ---

    void upload_pool(const HeightFieldView& pool) {
        if (pool.heights.empty()) return;
        if (pool.nx < 2 || pool.nz < 2 ||
            pool.heights.size() != std::size_t(pool.nx) * std::size_t(pool.nz)) {
            bad_frame("pool heights do not match its " + std::to_string(pool.nx) + "x" +
                      std::to_string(pool.nz) + " grid");
        }
        ensure_pool(pool.nx, pool.nz);
        write_height_field_vertices(pool, pool_vertices);
        buffer_sub_data(pool_vbo, 0, pool_vertices.size() * sizeof(float), pool_vertices.data());
        up.pool = true;
    }

    void upload_cylinders(const CylinderFrameView& cylinders) {
        if (cylinders.groups.empty()) return;
        if (max_cylinders == 0) bad_frame("cylinder groups given before set_cylinder_pool");
        const std::size_t vpc = layout.verts_per_cylinder();
        if (draw_counts.size() < 3 * cylinders.groups.size()) {
            draw_counts.resize(3 * cylinders.groups.size());
            draw_offsets.resize(3 * cylinders.groups.size());
            draw_base_vertices.resize(3 * cylinders.groups.size());
        }
        GLsizei draws = 0;
        const auto cap = static_cast<GLsizei>(layout.cap_index_count());
        for (const GroupDraw& g : cylinders.groups) {
            if (g.cylinder >= max_cylinders || g.vmin > g.vmax || g.vmax >= layout.v) {
                bad_frame("group (cylinder " + std::to_string(g.cylinder) + ", rings " +
                          std::to_string(g.vmin) + ".." + std::to_string(g.vmax) +
                          ") is outside the cylinder pool");
            }
            const std::size_t base = std::size_t(g.cylinder) * vpc;
            const std::size_t first = base + layout.ring_first_vertex(g.vmin);
            const std::size_t end = base + layout.ring_first_vertex(g.vmax + 1);
            if (end * 6u > cylinders.vertices.size())
                bad_frame("cylinder vertex array is too short for a group");
            buffer_sub_data(cylinder_vbo, first * kVertexBytes, (end - first) * kVertexBytes,
                            cylinders.vertices.data() + first * 6u);
            auto add = [&](std::size_t index_offset, std::size_t count) {
                draw_counts[draws] = static_cast<GLsizei>(count);
                draw_offsets[draws] = index_byte_offset(index_offset);
                draw_base_vertices[draws] = static_cast<GLint>(base);
                ++draws;
            };
            if (g.vmax > g.vmin) add(layout.band_index_offset(g.vmin), 6u * layout.u * (g.vmax - g.vmin));
            add(layout.top_cap_index_offset(g.vmin), std::size_t(cap));
            add(layout.bottom_cap_index_offset(g.vmax), std::size_t(cap));
        }
        up.cylinder_draws = draws;
    }

    void upload_mesh(const TriangleMeshView& mesh) {
        if (mesh.indices.empty()) return;
        if (mesh.vertices.size() % 6 != 0) bad_frame("mesh vertex array is not 6 floats per vertex");
        mesh_vbo.upload(mesh.vertices.data(), mesh.vertices.size() * sizeof(float));
        mesh_ibo.upload(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
        up.mesh_indices = static_cast<GLsizei>(mesh.indices.size());
    }

    void upload_spheres(std::span<const float> centers, float radius) {
        const std::size_t count = centers.size() / 3;
        if (count == 0 || radius <= 0) return;
        sphere_instances.upload(centers.data(), count * 3 * sizeof(float));
        up.spheres = static_cast<GLsizei>(count);
    }

    void upload_sprites(const ParticleSpritesView& p, float radius) {
        const std::size_t n = p.size();
        if (n == 0 || radius <= 0) return;
        if (p.y.size() != n || p.z.size() != n) bad_frame("sprite x, y and z differ in length");
        sprite_x.upload(p.x.data(), n * sizeof(float));
        sprite_y.upload(p.y.data(), n * sizeof(float));
        sprite_z.upload(p.z.data(), n * sizeof(float));
        up.sprites = static_cast<GLsizei>(n);
    }

    // --- draws, for whichever program is bound; `scale` is its u_scale ---

    void draw_range(IndexRange r) {
        if (r.count == 0) return;
        glBindVertexArray(static_vao);
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(r.count), GL_UNSIGNED_INT,
                       index_byte_offset(r.first));
    }

    // The tank moves with the container: its vertices read the offset as the constant of attribute 2.
    void draw_movers() {
        for (std::size_t i = 0; i < movers.size(); ++i) {
            if (movers[i].count == 0) continue;
            glVertexAttrib3f(2, mover_offsets[i].x, mover_offsets[i].y, mover_offsets[i].z);
            draw_range(movers[i]);
        }
        glVertexAttrib3f(2, 0, 0, 0);
    }

    void draw_tank_range(IndexRange r) {
        if (r.count == 0) return;
        glVertexAttrib3f(2, tank_offset.x, tank_offset.y, tank_offset.z);
        draw_range(r);
        glVertexAttrib3f(2, 0, 0, 0);
    }

    // `spheres`: the isolated spheres as instanced meshes too (the shadow pass draws them as points).
    void draw_fluid(GLuint program, GLint scale, GLint clip, bool spheres, bool mesh = true) {
        // Only programs that write gl_ClipDistance (clip >= 0) may have the planes enabled.
        const bool clipping = clip_fluid && clip >= 0;
        glProgramUniform1f(program, scale, 1.0f);
        if (clipping) {
            const Vec3f lo = glass_box.min + tank_offset, hi = glass_box.max + tank_offset;
            glProgramUniform4f(program, clip, lo.x, lo.z, hi.x, hi.z);
            for (GLenum plane = 0; plane < 4; ++plane) glEnable(GL_CLIP_DISTANCE0 + plane);
        }
        if (up.cylinder_draws > 0) {
            glBindVertexArray(cylinder_vao);
            glMultiDrawElementsBaseVertex(GL_TRIANGLES, draw_counts.data(), GL_UNSIGNED_INT,
                                          draw_offsets.data(), up.cylinder_draws, draw_base_vertices.data());
        }
        if (mesh && up.mesh_indices > 0) {
            glBindVertexArray(mesh_vao);
            glDrawElements(GL_TRIANGLES, up.mesh_indices, GL_UNSIGNED_INT, nullptr);
        }
        if (spheres && up.spheres > 0) {
            glProgramUniform1f(program, scale, up.radius);
            glBindVertexArray(sphere_vao);
            glDrawElementsInstanced(GL_TRIANGLES, sphere_index_count, GL_UNSIGNED_INT, nullptr, up.spheres);
            glProgramUniform1f(program, scale, 1.0f);
        }
        if (clipping) {
            for (GLenum plane = 0; plane < 4; ++plane) glDisable(GL_CLIP_DISTANCE0 + plane);
            glProgramUniform4f(program, clip, -kNoClip, -kNoClip, kNoClip, kNoClip);
        }
    }

    // Casters: solids, the tank's frame, the fluid (half a shadow: shaders.cpp kShadowFragment). The ground
    // and the pool only receive: nothing lies under them, and drawing them would only risk acne and cost
    // fill.
    void draw_shadow_pass() {
        shadow_map.begin();
        glUseProgram(shadow.id);
        glProgramUniform1f(shadow.id, shadow.scale, 1.0f);
        glProgramUniform1i(shadow.id, shadow.water, 0);
        draw_range(solids);
        draw_movers();
        draw_tank_range(tank_frame);
        glProgramUniform1i(shadow.id, shadow.water, 1);
        draw_fluid(shadow.id, shadow.scale, shadow.clip, false, up.mesh_casts_shadow);
        // Particles as round points: one vertex each instead of a sphere's 42 (vertices are shaded on this
        // thread alone, and a dam break has tens of thousands of particles).
        if (up.sprites + up.spheres > 0) {
            const float size = 2.0f * up.radius / shadow_fit.texel_world;
            glProgramUniform1f(shadow_points.id, shadow_points.point_size,
                               std::clamp(size, 1.0f, max_point_size));
            glProgramUniform1f(shadow_points.id, shadow_points.depth_radius,
                               up.radius / shadow_fit.depth_range);
            glEnable(GL_PROGRAM_POINT_SIZE);
            glUseProgram(shadow_points.id);
            if (up.sprites > 0) {
                glBindVertexArray(sprite_vao);
                glDrawArrays(GL_POINTS, 0, up.sprites);
            }
            if (up.spheres > 0) {
                glBindVertexArray(sphere_point_vao);
                glDrawArrays(GL_POINTS, 0, up.spheres);
            }
            glDisable(GL_PROGRAM_POINT_SIZE);
        }
        shadow_map.end(context.width(), context.height());
    }

    // After the shadow pass: its target must not be bound for sampling while it is drawn into.
    void bind_textures() {
        glActiveTexture(GL_TEXTURE0 + shaders::kEnvironmentUnit);
        glBindTexture(GL_TEXTURE_CUBE_MAP, environment.texture());
        glActiveTexture(GL_TEXTURE0 + shaders::kShadowUnit);
        glBindTexture(GL_TEXTURE_2D, shadow_map.texture());
        glActiveTexture(GL_TEXTURE0);
    }

    // After the opaque scene, at the far plane: only the pixels nothing covers pay for the cube map.
    void draw_sky() {
        glDepthFunc(GL_LEQUAL);
        glDepthMask(GL_FALSE);
        glUseProgram(sky.id);
        glBindVertexArray(empty_vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glDepthMask(GL_TRUE);
        glDepthFunc(GL_LESS);
    }

    const LitProgram& use_lit(int variant) {
        const LitProgram& p = lit[std::size_t(variant)];
        glUseProgram(p.id);
        return p;
    }

    void draw_static() {
        if (ground.count + ground_far.count > 0) {
            // Pushed back in depth so water lying exactly at ground height still wins.
            glEnable(GL_POLYGON_OFFSET_FILL);
            glPolygonOffset(2.0f, 8.0f);
            use_lit(shaders::kLitGround);
            draw_range(ground);
            use_lit(shaders::kLitGroundFar);
            draw_range(ground_far);
            glDisable(GL_POLYGON_OFFSET_FILL);
        }
        const LitProgram& solid = use_lit(shaders::kLitSolid);
        glProgramUniform3f(solid.id, solid.albedo, 0.60f, 0.60f, 0.62f);
        glProgramUniform1f(solid.id, solid.shine, 0.0f);
        draw_range(solids);
        draw_movers();
        // Dark anodised metal, so the frame reads as a frame against the pale floor and water.
        glProgramUniform3f(solid.id, solid.albedo, 0.24f, 0.25f, 0.27f);
        glProgramUniform1f(solid.id, solid.shine, 0.25f);
        draw_tank_range(tank_frame);
    }

    // Blended over what is already there, without writing depth, so later passes see through it.
    void draw_glass(IndexRange walls) {
        if (walls.count == 0) return;
        use_lit(shaders::kLitGlass);
        glEnable(GL_BLEND);
        glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);  // pictures stay opaque
        glDepthMask(GL_FALSE);
        draw_tank_range(walls);
        glDepthMask(GL_TRUE);
        glDisable(GL_BLEND);
    }

    bool has_fluid_surface() const { return up.cylinder_draws > 0 || up.mesh_indices > 0 || up.spheres > 0; }

    // The pool and the mesh methods' fluid, over the scene drawn so far, which they refract. The
    // thickness is of the whole closed surface: clipping it to the tank would open it, and a ray that
    // enters and never leaves sums to nonsense.
    void draw_water() {
        if (!up.pool && !has_fluid_surface()) return;
        backdrop.copy_scene();
        if (has_fluid_surface()) {
            backdrop.begin_thickness();
            glUseProgram(thickness.id);
            draw_fluid(thickness.id, thickness.scale, -1, false);
            if (up.spheres > 0) {
                glProgramUniform1f(thickness_points.id, thickness_points.radius, up.radius);
                glEnable(GL_PROGRAM_POINT_SIZE);
                glUseProgram(thickness_points.id);
                glBindVertexArray(sphere_point_vao);
                glDrawArrays(GL_POINTS, 0, up.spheres);
                glDisable(GL_PROGRAM_POINT_SIZE);
            }
            backdrop.end_thickness();
        }
        mark(&timings.water_thickness);
        backdrop.bind();
        if (up.pool) {
            const LitProgram& pool = use_lit(shaders::kLitPool);
            glProgramUniform1f(pool.id, pool.slab_depth, pool_depth);
            glBindVertexArray(pool_vao);
            glDrawElements(GL_TRIANGLES, pool_index_count, GL_UNSIGNED_INT, nullptr);
        }
        const LitProgram& water_program = use_lit(shaders::kLitWater);
        draw_fluid(water_program.id, water_program.scale, water_program.clip, true);
        mark(&timings.water);
    }

    // With time_passes: waits for GL and charges the time since the last mark to `slot`.
    void mark(double* slot) {
        if (!time_passes) return;
        glFinish();
        const auto now = std::chrono::steady_clock::now();
        // Added, not set: the front glass and the final wait are one part with the diffuse pass between.
        if (slot) *slot += std::chrono::duration<double, std::milli>(now - mark_time).count();
        mark_time = now;
    }

    void render(const FrameView& frame) {
        context.make_current();
        timings = {};
        mark(nullptr);
        up = {};
        up.radius = frame.sphere_radius;
        up.mesh_casts_shadow = frame.mesh_casts_shadow;
        upload_pool(frame.pool);
        upload_cylinders(frame.cylinders);
        upload_mesh(frame.mesh);
        upload_spheres(frame.sphere_centers, frame.sphere_radius);
        upload_sprites(frame.sprites, frame.sphere_radius);
        mark(&timings.upload);
        if (frame.volume.stored() > 0 && !volume)
            bad_frame("a density volume given before set_volume_raycast");
        if (volume) {
            volume->upload(frame.volume);
            mark(&timings.volume_upload);
        }
        draw_shadow_pass();
        mark(&timings.shadow);
        bind_textures();
        glClear(GL_DEPTH_BUFFER_BIT);
        draw_static();
        draw_sky();
        draw_glass(glass_back);
        mark(&timings.scene);
        draw_water();
        if (screen) {
            screen->render(frame.sprites, frame.spray, frame.sphere_radius, frame.sprite_spacing);
            mark(&timings.screen);
        }
        if (volume) {
            // As the mesh methods' water (draw_fluid): inside the tank's glass, across x and z only, so
            // what splashes over its top still shows.
            if (clip_fluid) {
                const Vec3f lo = glass_box.min + tank_offset, hi = glass_box.max + tank_offset;
                volume->set_clip({lo.x, -kNoClip, lo.z}, {hi.x, kNoClip, hi.z});
            } else {
                volume->clear_clip();
            }
            volume->draw();
            mark(&timings.volume);
        }
        draw_glass(glass_front);
        // Last, over everything the scene drew: translucent sprites that write no depth.
        if (!frame.diffuse.sprites.empty()) {
            if (!diffuse) bad_frame("diffuse sprites given before set_diffuse_sprites");
            mark(&timings.finish);
            diffuse->draw(frame.diffuse);
            mark(&timings.diffuse);
        }
        glBindVertexArray(0);
        glFinish();
        mark(&timings.finish);
#ifndef NDEBUG
        check_gl("Renderer::render");
#endif
    }
};

Renderer::Renderer(const RenderSettings& settings)
    : impl_(std::make_unique<Impl>(settings.width, settings.height)) {}

Renderer::~Renderer() = default;

void Renderer::set_scene(const SceneDesc& scene) {
    impl_->set_scene(scene);
}

void Renderer::set_container_offset(Vec3f offset) {
    impl_->tank_offset = offset;
}

void Renderer::set_mover_offsets(std::span<const Vec3f> centres) {
    const std::size_t n = std::min(centres.size(), impl_->mover_offsets.size());
    std::copy_n(centres.begin(), n, impl_->mover_offsets.begin());
}

void Renderer::set_cylinder_pool(const CylinderLayout& layout, std::uint32_t max_cylinders) {
    impl_->set_cylinder_pool(layout, max_cylinders);
}

void Renderer::set_screen_fluid(const ScreenFluidSettings& settings) {
    impl_->set_screen_fluid(settings);
}

void Renderer::set_volume_raycast(const VolumeRaycastSettings& settings) {
    impl_->set_volume_raycast(settings);
}

void Renderer::set_diffuse_sprites(std::uint32_t max_sprites) {
    impl_->set_diffuse_sprites(max_sprites);
}

void Renderer::render(const FrameView& frame) {
    impl_->render(frame);
}

const ScreenFluidPass& Renderer::screen_fluid() const {
    if (!impl_->screen) throw std::logic_error("Renderer::screen_fluid: no screen-space fluid pass");
    return *impl_->screen;
}

const VolumePass& Renderer::volume_pass() const {
    if (!impl_->volume) throw std::logic_error("Renderer::volume_pass: no volume raycast pass");
    return *impl_->volume;
}

void Renderer::set_time_passes(bool on) {
    impl_->time_passes = on;
}

const RenderTimings& Renderer::timings() const {
    return impl_->timings;
}

const WaterBackdrop& Renderer::water_backdrop() const {
    return impl_->backdrop;
}

const EnvironmentMap& Renderer::environment() const {
    return impl_->environment;
}

int Renderer::width() const {
    return impl_->context.width();
}
int Renderer::height() const {
    return impl_->context.height();
}

void Renderer::read_rgba(std::span<std::uint8_t> out) const {
    const std::size_t row = std::size_t(width()) * 4u, rows = std::size_t(height());
    if (out.size() < row * rows) {
        throw std::invalid_argument("Renderer::read_rgba: buffer holds " + std::to_string(out.size()) +
                                    " bytes, needs " + std::to_string(row * rows));
    }
    // OSMesa stores rows bottom-up; callers (PNG, tests) want the top row first.
    const std::span<const std::uint8_t> pixels = impl_->context.pixels();
    for (std::size_t y = 0; y < rows; ++y) {
        std::memcpy(out.data() + y * row, pixels.data() + (rows - 1 - y) * row, row);
    }
}

std::string Renderer::gl_version() const {
    return impl_->context.version();
}
std::string Renderer::gl_renderer() const {
    return impl_->context.renderer();
}

}  // namespace rivulet
