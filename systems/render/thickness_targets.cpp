#include "systems/render/thickness_targets.h"

#include <stdexcept>

#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/shaders.h"

namespace rivulet {

ThicknessTargets::ThicknessTargets(int width, int height) : width_(width), height_(height) {
    signed_sum_ = create_texture_2d(GL_R32F, width, height, GL_NEAREST);
    span_ = create_texture_2d(GL_RG32F, width, height, GL_NEAREST);
    thickness_ = create_texture_2d(GL_R32F, width, height, GL_LINEAR);
    accumulate_fbo_ = create_framebuffer({signed_sum_, span_}, 0, "ThicknessTargets (accumulation)");
    thickness_fbo_ = create_framebuffer({thickness_}, 0, "ThicknessTargets");
    const GLuint vs =
        compile_shader(GL_VERTEX_SHADER, {shaders::kFullScreenVertex}, "thickness_resolve.vert");
    const GLuint fs =
        compile_shader(GL_FRAGMENT_SHADER, {shaders::kThicknessResolveFragment}, "thickness_resolve.frag");
    resolve_ = link_program(vs, fs, "thickness_resolve");
    glProgramUniform1i(resolve_, uniform_location(resolve_, "u_signed_sum", "thickness_resolve"), 0);
    glProgramUniform1i(resolve_, uniform_location(resolve_, "u_span", "thickness_resolve"), 1);
    glGenVertexArrays(1, &empty_vao_);
    check_gl("ThicknessTargets setup");
}

ThicknessTargets::~ThicknessTargets() {
    glDeleteProgram(resolve_);
    glDeleteVertexArrays(1, &empty_vao_);
    const GLuint fbos[] = {accumulate_fbo_, thickness_fbo_};
    glDeleteFramebuffers(2, fbos);
    const GLuint textures[] = {signed_sum_, span_, thickness_};
    glDeleteTextures(3, textures);
}

void ThicknessTargets::begin() {
    glBindFramebuffer(GL_FRAMEBUFFER, accumulate_fbo_);
    glViewport(0, 0, width_, height_);
    const float zero[4] = {0, 0, 0, 0}, span_clear[4] = {0, -3.0e38f, 0, 0};  // x 0: no fluid drawn
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferfv(GL_COLOR, 1, span_clear);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquationi(0, GL_FUNC_ADD);
    glBlendEquationi(1, GL_MAX);
}

void ThicknessTargets::resolve() {
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    glBindFramebuffer(GL_FRAMEBUFFER, thickness_fbo_);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, signed_sum_);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, span_);
    glUseProgram(resolve_);
    glBindVertexArray(empty_vao_);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glActiveTexture(GL_TEXTURE0);
}

void ThicknessTargets::read(std::span<float> out) const {
    if (out.size() < std::size_t(width_) * std::size_t(height_))
        throw std::invalid_argument("ThicknessTargets::read: buffer too small");
    glBindFramebuffer(GL_READ_FRAMEBUFFER, thickness_fbo_);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, width_, height_, GL_RED, GL_FLOAT, out.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace rivulet
