#include "systems/render/water_backdrop.h"

#include <initializer_list>
#include <stdexcept>
#include <string>

#include "systems/render/gl_program.h"
#include "systems/render/shaders.h"

namespace rivulet {
namespace {

GLuint framebuffer(std::initializer_list<GLuint> colors, const char* what) {
    GLuint f = 0;
    glGenFramebuffers(1, &f);
    glBindFramebuffer(GL_FRAMEBUFFER, f);
    GLenum attachment = GL_COLOR_ATTACHMENT0;
    for (GLuint c : colors) glFramebufferTexture2D(GL_FRAMEBUFFER, attachment++, GL_TEXTURE_2D, c, 0);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
        glDeleteFramebuffers(1, &f);
        throw std::runtime_error(std::string("WaterBackdrop: the ") + what + " target is incomplete (" +
                                 std::to_string(status) + ")");
    }
    return f;
}

GLuint linear_texture(GLenum internal_format, int width, int height) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal_format, width, height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

}  // namespace

WaterBackdrop::WaterBackdrop(int width, int height)
    : width_(width),
      height_(height),
      thick_w_((width + kThicknessDownsample - 1) / kThicknessDownsample),
      thick_h_((height + kThicknessDownsample - 1) / kThicknessDownsample) {
    scene_color_ = linear_texture(GL_RGBA8, width, height);
    thickness_ = linear_texture(GL_R32F, thick_w_, thick_h_);
    signed_sum_ = linear_texture(GL_R32F, thick_w_, thick_h_);
    span_ = linear_texture(GL_RG32F, thick_w_, thick_h_);
    thickness_fbo_ = framebuffer({thickness_}, "thickness");
    accumulate_fbo_ = framebuffer({signed_sum_, span_}, "thickness accumulation");
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, {shaders::kThicknessResolveVertex}, "resolve.vert");
    const GLuint fs =
        compile_shader(GL_FRAGMENT_SHADER, {shaders::kThicknessResolveFragment}, "resolve.frag");
    resolve_ = link_program(vs, fs, "thickness_resolve");
    glProgramUniform1i(resolve_, uniform_location(resolve_, "u_signed_sum", "thickness_resolve"), 0);
    glProgramUniform1i(resolve_, uniform_location(resolve_, "u_span", "thickness_resolve"), 1);
    glGenVertexArrays(1, &empty_vao_);
    check_gl("WaterBackdrop setup");
}

WaterBackdrop::~WaterBackdrop() {
    glDeleteProgram(resolve_);
    glDeleteVertexArrays(1, &empty_vao_);
    const GLuint fbos[] = {thickness_fbo_, accumulate_fbo_};
    glDeleteFramebuffers(2, fbos);
    const GLuint textures[] = {scene_color_, thickness_, signed_sum_, span_};
    glDeleteTextures(4, textures);
}

void WaterBackdrop::copy_scene() {
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneColorUnit);
    glBindTexture(GL_TEXTURE_2D, scene_color_);
    glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width_, height_);
    glActiveTexture(GL_TEXTURE0);
}

void WaterBackdrop::begin_thickness() {
    glBindFramebuffer(GL_FRAMEBUFFER, accumulate_fbo_);
    const GLenum buffers[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
    glDrawBuffers(2, buffers);
    glViewport(0, 0, thick_w_, thick_h_);
    const float zero[4] = {0, 0, 0, 0}, span_clear[4] = {0, -3.0e38f, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    glClearBufferfv(GL_COLOR, 1, span_clear);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glBlendEquationi(0, GL_FUNC_ADD);
    glBlendEquationi(1, GL_MAX);
}

void WaterBackdrop::end_thickness() {
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
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width_, height_);
}

void WaterBackdrop::bind() const {
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneColorUnit);
    glBindTexture(GL_TEXTURE_2D, scene_color_);
    glActiveTexture(GL_TEXTURE0 + shaders::kThicknessUnit);
    glBindTexture(GL_TEXTURE_2D, thickness_);
    glActiveTexture(GL_TEXTURE0);
}

void WaterBackdrop::read_thickness(std::span<float> out) const {
    if (out.size() < std::size_t(thick_w_) * std::size_t(thick_h_))
        throw std::invalid_argument("WaterBackdrop::read_thickness: buffer too small");
    glBindFramebuffer(GL_READ_FRAMEBUFFER, thickness_fbo_);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glReadPixels(0, 0, thick_w_, thick_h_, GL_RED, GL_FLOAT, out.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
}

}  // namespace rivulet
