#include "systems/render/sprite_pass.h"

#include <cstddef>
#include <stdexcept>
#include <string>

#include "systems/render/camera.h"
#include "systems/render/gl.h"
#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/sprite_shaders.h"

namespace rivulet {
namespace {

// The vertex layout is the frame's own struct, uploaded as it is: no repacking on the render thread.
static_assert(sizeof(DiffuseSprite) == 5 * sizeof(float));
static_assert(offsetof(DiffuseSprite, size) == 3 * sizeof(float));
static_assert(offsetof(DiffuseSprite, rgba) == 4 * sizeof(float));

// The GL state draw() changes, to put back afterwards: other passes assume the renderer's defaults.
struct SavedState {
    GLboolean blend, depth_test, point_size, depth_mask;
    GLint depth_func, src_rgb, dst_rgb, src_alpha, dst_alpha, program, vao;

    static SavedState take() {
        SavedState s{};
        s.blend = glIsEnabled(GL_BLEND);
        s.depth_test = glIsEnabled(GL_DEPTH_TEST);
        s.point_size = glIsEnabled(GL_PROGRAM_POINT_SIZE);
        glGetBooleanv(GL_DEPTH_WRITEMASK, &s.depth_mask);
        glGetIntegerv(GL_DEPTH_FUNC, &s.depth_func);
        glGetIntegerv(GL_BLEND_SRC_RGB, &s.src_rgb);
        glGetIntegerv(GL_BLEND_DST_RGB, &s.dst_rgb);
        glGetIntegerv(GL_BLEND_SRC_ALPHA, &s.src_alpha);
        glGetIntegerv(GL_BLEND_DST_ALPHA, &s.dst_alpha);
        glGetIntegerv(GL_CURRENT_PROGRAM, &s.program);
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &s.vao);
        return s;
    }

    static void set(GLenum cap, GLboolean on) {
        if (on)
            glEnable(cap);
        else
            glDisable(cap);
    }

    void restore() const {
        set(GL_BLEND, blend);
        set(GL_DEPTH_TEST, depth_test);
        set(GL_PROGRAM_POINT_SIZE, point_size);
        glDepthMask(depth_mask);
        glDepthFunc(static_cast<GLenum>(depth_func));
        glBlendFuncSeparate(static_cast<GLenum>(src_rgb), static_cast<GLenum>(dst_rgb),
                            static_cast<GLenum>(src_alpha), static_cast<GLenum>(dst_alpha));
        glUseProgram(static_cast<GLuint>(program));
        glBindVertexArray(static_cast<GLuint>(vao));
    }
};

}  // namespace

struct SpritePass::Impl {
    std::uint32_t max_sprites;
    int width, height;
    GLuint program = 0, vbo = 0, ibo = 0, vao = 0;
    GLint view_proj = -1, pixels_per_unit = -1;

    Impl(std::uint32_t max, int w, int h) : max_sprites(max), width(w), height(h) {
        const GLuint vs =
            compile_shader(GL_VERTEX_SHADER, {shaders::kDiffuseSpriteVertex}, "diffuse_sprite.vert");
        GLuint fs = 0;
        try {
            fs = compile_shader(GL_FRAGMENT_SHADER, {shaders::kDiffuseSpriteFragment}, "diffuse_sprite.frag");
        } catch (...) {
            glDeleteShader(vs);
            throw;
        }
        program = link_program(vs, fs, "diffuse_sprite");
        view_proj = uniform_location(program, "u_view_proj", "diffuse_sprite");
        pixels_per_unit = uniform_location(program, "u_pixels_per_unit", "diffuse_sprite");
        // llvmpipe rasterizes points up to its limit (255 px) and refuses larger ones; clamping keeps a
        // sprite right at the camera drawn, if smaller than it should be.
        float sizes[2] = {1, 1};
        glGetFloatv(GL_POINT_SIZE_RANGE, sizes);
        glProgramUniform1f(program, uniform_location(program, "u_max_point_size", "diffuse_sprite"),
                           sizes[1]);

        vbo = create_buffer();
        buffer_data(vbo, std::size_t(max) * sizeof(DiffuseSprite), nullptr, GL_DYNAMIC_DRAW);
        glGenVertexArrays(1, &vao);
        glBindVertexArray(vao);
        glBindVertexBuffer(0, vbo, 0, sizeof(DiffuseSprite));
        glEnableVertexAttribArray(0);
        glVertexAttribFormat(0, 4, GL_FLOAT, GL_FALSE, 0);
        glVertexAttribBinding(0, 0);
        // RGBA8 with r in the low byte is bytes r, g, b, a in memory on the little-endian hosts we run on.
        glEnableVertexAttribArray(1);
        glVertexAttribFormat(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, offsetof(DiffuseSprite, rgba));
        glVertexAttribBinding(1, 0);
        // The draw order, bound to the vertex array (indices into the sprites as the workers left them).
        ibo = create_buffer();
        buffer_data(ibo, std::size_t(max) * sizeof(std::uint32_t), nullptr, GL_DYNAMIC_DRAW);
        glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
        glBindVertexArray(0);
        set_camera(CameraDesc{});
        check_gl("SpritePass setup");
    }

    ~Impl() {
        glDeleteVertexArrays(1, &vao);
        glDeleteBuffers(1, &vbo);
        glDeleteBuffers(1, &ibo);
        glDeleteProgram(program);
    }

    void set_camera(const CameraDesc& camera) {
        const Mat4 vp = view_projection(camera, static_cast<float>(width) / static_cast<float>(height));
        glProgramUniformMatrix4fv(program, view_proj, 1, GL_FALSE, vp.data());
        // viewport_height * P[1][1] / 2, with P[1][1] = 1 / tan(fov_y / 2).
        glProgramUniform1f(program, pixels_per_unit,
                           0.5f * static_cast<float>(height) / camera_basis(camera).tan_half_fov_y);
    }

    void draw(const DiffuseSpritesView& view) {
        const std::size_t n = view.sprites.size();
        if (n == 0) return;
        if (n > max_sprites) {
            throw std::out_of_range("SpritePass::draw: " + std::to_string(n) + " sprites, room for " +
                                    std::to_string(max_sprites));
        }
        if (!view.order.empty() && view.order.size() != n) {
            throw std::invalid_argument("SpritePass::draw: an order of " + std::to_string(view.order.size()) +
                                        " for " + std::to_string(n) + " sprites");
        }
        buffer_sub_data(vbo, 0, n * sizeof(DiffuseSprite), view.sprites.data());
        if (!view.order.empty()) buffer_sub_data(ibo, 0, n * sizeof(std::uint32_t), view.order.data());
        const SavedState saved = SavedState::take();
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_FALSE);  // translucent: what lies behind a sprite must still be drawn after it
        glEnable(GL_BLEND);
        // The picture's alpha stays as it was (opaque); colour is premultiplied by the shader.
        if (view.additive)
            glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ZERO, GL_ONE);
        else
            glBlendFuncSeparate(GL_ONE, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
        glEnable(GL_PROGRAM_POINT_SIZE);
        glUseProgram(program);
        glBindVertexArray(vao);
        if (view.order.empty())
            glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(n));
        else
            glDrawElements(GL_POINTS, static_cast<GLsizei>(n), GL_UNSIGNED_INT, nullptr);
        saved.restore();
    }
};

SpritePass::SpritePass(std::uint32_t max_sprites, int width, int height)
    : impl_(std::make_unique<Impl>(max_sprites, width, height)) {}

SpritePass::~SpritePass() = default;

void SpritePass::set_camera(const CameraDesc& camera) {
    impl_->set_camera(camera);
}

void SpritePass::draw(const DiffuseSpritesView& view) {
    impl_->draw(view);
}

std::uint32_t SpritePass::max_sprites() const {
    return impl_->max_sprites;
}

}  // namespace rivulet
