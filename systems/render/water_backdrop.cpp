#include "systems/render/water_backdrop.h"

#include "systems/render/gl_buffer.h"
#include "systems/render/gl_program.h"
#include "systems/render/shaders.h"

namespace rivulet {

WaterBackdrop::WaterBackdrop(int width, int height)
    : width_(width),
      height_(height),
      thickness_((width + kThicknessDownsample - 1) / kThicknessDownsample,
                 (height + kThicknessDownsample - 1) / kThicknessDownsample) {
    scene_color_ = create_texture_2d(GL_RGBA8, width, height, GL_LINEAR);
    scene_depth_ = create_texture_2d(GL_DEPTH_COMPONENT24, width, height, GL_NEAREST);
    check_gl("WaterBackdrop setup");
}

WaterBackdrop::~WaterBackdrop() {
    glDeleteTextures(1, &scene_color_);
    glDeleteTextures(1, &scene_depth_);
}

void WaterBackdrop::copy_scene() {
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneColorUnit);
    glBindTexture(GL_TEXTURE_2D, scene_color_);
    glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width_, height_);
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneDepthUnit);
    glBindTexture(GL_TEXTURE_2D, scene_depth_);
    glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width_, height_);
    glActiveTexture(GL_TEXTURE0);
}

void WaterBackdrop::begin_thickness() {
    thickness_.begin();
}

void WaterBackdrop::end_thickness() {
    thickness_.resolve();
    glEnable(GL_DEPTH_TEST);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, width_, height_);
}

void WaterBackdrop::bind() const {
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneColorUnit);
    glBindTexture(GL_TEXTURE_2D, scene_color_);
    glActiveTexture(GL_TEXTURE0 + shaders::kSceneDepthUnit);
    glBindTexture(GL_TEXTURE_2D, scene_depth_);
    glActiveTexture(GL_TEXTURE0 + shaders::kThicknessUnit);
    glBindTexture(GL_TEXTURE_2D, thickness_.texture());
    glActiveTexture(GL_TEXTURE0);
}

void WaterBackdrop::read_thickness(std::span<float> out) const {
    thickness_.read(out);
}

}  // namespace rivulet
