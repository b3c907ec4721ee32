#pragma once
// What the lit water of the mesh methods reads besides its own surface (Janisz §3.1.4, the composite
// the screen-space method uses): the picture drawn before the water, refracted through it, and the
// thickness of the fluid along each pixel's ray, absorbed over. Owned by the Renderer, in its context.
#include <span>

#include "systems/render/gl.h"
#include "systems/render/thickness_targets.h"

namespace rivulet {

class WaterBackdrop {
  public:
    static constexpr int kThicknessDownsample = 2;

    // Throws std::runtime_error when a target cannot be made.
    WaterBackdrop(int width, int height);
    ~WaterBackdrop();
    WaterBackdrop(const WaterBackdrop&) = delete;
    WaterBackdrop& operator=(const WaterBackdrop&) = delete;

    // Copies the default framebuffer's colour and depth: the scene the water is drawn over.
    void copy_scene();
    // ThicknessTargets::begin; the caller draws the closed fluid surfaces with the thickness programs
    // (shaders::kMeshThicknessFragment, kSphereThicknessPointFragment). end_thickness() resolves them and
    // restores the default framebuffer, the full viewport, blending off and the depth test on.
    void begin_thickness();
    void end_thickness();
    // Binds the scene copy and the thickness to their texture units (shaders::kSceneColorUnit,
    // shaders::kSceneDepthUnit, shaders::kThicknessUnit).
    void bind() const;

    int thickness_width() const { return thickness_.width(); }
    int thickness_height() const { return thickness_.height(); }
    // thickness_width() x thickness_height() floats, rows bottom to top (tests).
    void read_thickness(std::span<float> out) const;

  private:
    int width_, height_;
    ThicknessTargets thickness_;
    GLuint scene_color_ = 0, scene_depth_ = 0;
};

}  // namespace rivulet
