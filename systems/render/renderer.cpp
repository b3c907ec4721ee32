#include "systems/render/renderer.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "jobs/low_res_sphere.h"
#include "systems/render/camera.h"
#include "systems/render/gl.h"
#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/osmesa_context.h"
#include "systems/render/render_programs.h"
#include "systems/render/scene_geometry.h"
#include "systems/render/shaders.h"

namespace rivulet {
namespace {

constexpr int kMinSize = 16, kMaxSize = 8192;
constexpr std::size_t kVertexBytes = 6 * sizeof(float);

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
    LitProgram lit;
    SkyProgram sky;
    GLuint empty_vao = 0;  // the sky draws from gl_VertexID, but core profile still wants a VAO bound

    GLuint static_vbo = 0, static_ibo = 0, static_vao = 0;
    GLsizei ground_index_count = 0, collider_index_count = 0;

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

    std::unique_ptr<ScreenFluidPass> screen;
    CameraDesc camera_desc;  // of the scene, for passes set up after it
    Vec3f light{0, 1, 0};

    GLuint pool_vbo = 0, pool_ibo = 0, pool_vao = 0;
    int pool_nx = 0, pool_nz = 0;
    GLsizei pool_index_count = 0;
    std::vector<float> pool_vertices;

    Impl(int width, int height) : context(checked_size(width, "width"), checked_size(height, "height")) {
        lit = build_lit_program();
        sky = build_sky_program();
        glGenVertexArrays(1, &empty_vao);
        create_static_objects();
        create_sphere_objects();
        mesh_vbo.create();
        mesh_ibo.create();
        mesh_vao = create_mesh_vao(mesh_vbo.id, mesh_ibo.id);
        cylinder_vbo = create_buffer();
        cylinder_ibo = create_buffer();
        cylinder_vao = create_mesh_vao(cylinder_vbo, cylinder_ibo);
        pool_vbo = create_buffer();
        pool_ibo = create_buffer();
        pool_vao = create_mesh_vao(pool_vbo, pool_ibo);
        glViewport(0, 0, width, height);
        glDisable(GL_CULL_FACE);
        glDepthFunc(GL_LESS);
        apply_camera(CameraDesc{});
        check_gl("renderer setup");
    }

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

    void apply_camera(const CameraDesc& camera) {
        const float aspect = static_cast<float>(context.width()) / static_cast<float>(context.height());
        const Mat4 vp = view_projection(camera, aspect);
        const CameraBasis b = camera_basis(camera);
        // Light from above and behind the viewer, slightly to the right, so what faces the camera is lit.
        Vec3f back = camera.eye - camera.target;
        back.y = 0;
        back = length(back) > 1e-6f ? normalize(back) : Vec3f{0, 0, 1};
        light = normalize(Vec3f{0, 1, 0} + back * 0.6f + b.right * 0.35f);
        camera_desc = camera;
        if (screen) screen->set_camera(camera, light);
        glProgramUniformMatrix4fv(lit.id, lit.view_proj, 1, GL_FALSE, vp.m);
        glProgramUniform3f(lit.id, lit.eye, b.eye.x, b.eye.y, b.eye.z);
        glProgramUniform3f(lit.id, lit.light_dir, light.x, light.y, light.z);
        glProgramUniform3f(sky.id, sky.forward, b.forward.x, b.forward.y, b.forward.z);
        glProgramUniform3f(sky.id, sky.right, b.right.x, b.right.y, b.right.z);
        glProgramUniform3f(sky.id, sky.up, b.up.x, b.up.y, b.up.z);
        glProgramUniform2f(sky.id, sky.half_extent, b.tan_half_fov_y * aspect, b.tan_half_fov_y);
    }

    void set_scene(const SceneDesc& scene) {
        context.make_current();
        apply_camera(scene.camera);
        const StaticGeometry g = build_static_geometry(scene);
        buffer_data(static_vbo, g.vertices.size() * sizeof(float), g.vertices.data(), GL_STATIC_DRAW);
        buffer_data(static_ibo, g.indices.size() * sizeof(std::uint32_t), g.indices.data(), GL_STATIC_DRAW);
        ground_index_count = static_cast<GLsizei>(g.ground_index_count);
        collider_index_count = static_cast<GLsizei>(g.indices.size() - g.ground_index_count);
        if (scene.pool.enabled) ensure_pool(scene.pool.nx, scene.pool.nz);
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
    }

    void draw_sky() {
        glDisable(GL_DEPTH_TEST);
        glDepthMask(GL_FALSE);
        glUseProgram(sky.id);
        glBindVertexArray(empty_vao);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        glEnable(GL_DEPTH_TEST);
        glDepthMask(GL_TRUE);
        glClear(GL_DEPTH_BUFFER_BIT);
    }

    void draw_static() {
        if (ground_index_count > 0) {
            // Pushed back in depth so water lying exactly at ground height still wins.
            glEnable(GL_POLYGON_OFFSET_FILL);
            glPolygonOffset(2.0f, 8.0f);
            glProgramUniform1i(lit.id, lit.material, shaders::kMaterialGround);
            glBindVertexArray(static_vao);
            glDrawElements(GL_TRIANGLES, ground_index_count, GL_UNSIGNED_INT, nullptr);
            glDisable(GL_POLYGON_OFFSET_FILL);
        }
        if (collider_index_count > 0) {
            glProgramUniform1i(lit.id, lit.material, shaders::kMaterialCollider);
            glBindVertexArray(static_vao);
            glDrawElements(GL_TRIANGLES, collider_index_count, GL_UNSIGNED_INT,
                           index_byte_offset(std::size_t(ground_index_count)));
        }
    }

    void draw_pool(const HeightFieldView& pool) {
        if (pool.heights.empty()) return;
        if (pool.nx < 2 || pool.nz < 2 ||
            pool.heights.size() != std::size_t(pool.nx) * std::size_t(pool.nz)) {
            bad_frame("pool heights do not match its " + std::to_string(pool.nx) + "x" +
                      std::to_string(pool.nz) + " grid");
        }
        ensure_pool(pool.nx, pool.nz);
        write_height_field_vertices(pool, pool_vertices);
        buffer_sub_data(pool_vbo, 0, pool_vertices.size() * sizeof(float), pool_vertices.data());
        glBindVertexArray(pool_vao);
        glDrawElements(GL_TRIANGLES, pool_index_count, GL_UNSIGNED_INT, nullptr);
    }

    void draw_cylinders(const CylinderFrameView& cylinders) {
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
        glBindVertexArray(cylinder_vao);
        glMultiDrawElementsBaseVertex(GL_TRIANGLES, draw_counts.data(), GL_UNSIGNED_INT, draw_offsets.data(),
                                      draws, draw_base_vertices.data());
    }

    void draw_mesh(const TriangleMeshView& mesh) {
        if (mesh.indices.empty()) return;
        if (mesh.vertices.size() % 6 != 0) bad_frame("mesh vertex array is not 6 floats per vertex");
        mesh_vbo.upload(mesh.vertices.data(), mesh.vertices.size() * sizeof(float));
        mesh_ibo.upload(mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
        glBindVertexArray(mesh_vao);
        glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    }

    void draw_spheres(std::span<const float> centers, float radius) {
        const std::size_t count = centers.size() / 3;
        if (count == 0 || radius <= 0) return;
        sphere_instances.upload(centers.data(), count * 3 * sizeof(float));
        glProgramUniform1f(lit.id, lit.scale, radius);
        glBindVertexArray(sphere_vao);
        glDrawElementsInstanced(GL_TRIANGLES, sphere_index_count, GL_UNSIGNED_INT, nullptr,
                                static_cast<GLsizei>(count));
    }

    void render(const FrameView& frame) {
        context.make_current();
        draw_sky();
        glUseProgram(lit.id);
        glProgramUniform1f(lit.id, lit.scale, 1.0f);
        draw_static();
        glProgramUniform1i(lit.id, lit.material, shaders::kMaterialWater);
        draw_pool(frame.pool);
        draw_cylinders(frame.cylinders);
        draw_mesh(frame.mesh);
        draw_spheres(frame.sphere_centers, frame.sphere_radius);
        if (screen) screen->render(frame.sprites, frame.sphere_radius);
        glBindVertexArray(0);
        glFinish();
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

void Renderer::set_cylinder_pool(const CylinderLayout& layout, std::uint32_t max_cylinders) {
    impl_->set_cylinder_pool(layout, max_cylinders);
}

void Renderer::set_screen_fluid(const ScreenFluidSettings& settings) {
    impl_->set_screen_fluid(settings);
}

void Renderer::render(const FrameView& frame) {
    impl_->render(frame);
}

const ScreenFluidPass& Renderer::screen_fluid() const {
    if (!impl_->screen) throw std::logic_error("Renderer::screen_fluid: no screen-space fluid pass");
    return *impl_->screen;
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
