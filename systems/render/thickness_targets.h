#pragma once
// The fluid's thickness along each pixel's ray, for the water's absorption (Janisz §3.1.3), shared by
// the mesh methods' water and the screen-space pass. The caller draws its surfaces into two targets: a
// signed sum of distances (additive blending; shaders::kMeshThicknessFragment, kSphereThicknessFragment)
// and the span from the farthest exit to the nearest entry (GL_MAX). The resolve
// (shaders::kThicknessResolveFragment) keeps the sum where it lies within the span and takes the span
// otherwise, so overlapping surfaces count their common water once.
#include <span>

#include "systems/render/gl.h"

namespace rivulet {

class ThicknessTargets {
  public:
    // Targets of width x height (the reduced size); throws std::runtime_error when GL cannot make them.
    ThicknessTargets(int width, int height);
    ~ThicknessTargets();
    ThicknessTargets(const ThicknessTargets&) = delete;
    ThicknessTargets& operator=(const ThicknessTargets&) = delete;

    // Binds the two targets cleared, with their blending, the depth test off and the viewport on them.
    void begin();
    // Resolves them into texture() and leaves its framebuffer bound, blending off, texture unit 0 active.
    void resolve();

    GLuint texture() const { return thickness_; }  // linear filtering
    GLuint framebuffer() const { return thickness_fbo_; }
    int width() const { return width_; }
    int height() const { return height_; }
    // width() x height() floats of texture(), rows bottom to top.
    void read(std::span<float> out) const;

  private:
    int width_, height_;
    GLuint signed_sum_ = 0, span_ = 0, thickness_ = 0;
    GLuint accumulate_fbo_ = 0, thickness_fbo_ = 0;
    GLuint resolve_ = 0, empty_vao_ = 0;
};

}  // namespace rivulet
