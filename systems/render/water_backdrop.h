#pragma once
// What the lit water of the mesh methods reads besides its own surface (seed 004 §3.1.4, the composite
// the screen-space method uses): the picture drawn before the water, refracted through it, and the
// thickness of the fluid along each pixel's ray, absorbed over. Owned by the Renderer, in its context.
#include <span>

#include "systems/render/gl.h"

namespace rivulet {

class WaterBackdrop {
  public:
    static constexpr int kThicknessDownsample = 2;

    // Throws std::runtime_error when a target cannot be made.
    WaterBackdrop(int width, int height);
    ~WaterBackdrop();
    WaterBackdrop(const WaterBackdrop&) = delete;
    WaterBackdrop& operator=(const WaterBackdrop&) = delete;

    // Copies the default framebuffer's colour: the scene the water is drawn over.
    void copy_scene();
    // Binds the cleared thickness targets with their blending and no depth test; the caller draws the
    // closed fluid surfaces with the thickness program (shaders::kMeshThicknessFragment).
    // end_thickness() resolves them into one thickness per pixel and restores the default framebuffer,
    // the full viewport, blending off and the depth test on.
    void begin_thickness();
    void end_thickness();
    // Binds the scene copy and the thickness to their texture units (shaders::kSceneColorUnit,
    // shaders::kThicknessUnit).
    void bind() const;

    int thickness_width() const { return thick_w_; }
    int thickness_height() const { return thick_h_; }
    // thickness_width() x thickness_height() floats, rows bottom to top (tests).
    void read_thickness(std::span<float> out) const;

  private:
    int width_, height_, thick_w_, thick_h_;
    GLuint scene_color_ = 0, thickness_ = 0, thickness_fbo_ = 0;
    GLuint signed_sum_ = 0, span_ = 0, accumulate_fbo_ = 0;
    GLuint resolve_ = 0, empty_vao_ = 0;
};

}  // namespace rivulet
