#pragma once
// Screen-space fluid rendering (van der Laan, Green & Sainz 2009; seed 004 §3.1): particles are drawn as
// spheres into a linear eye-space depth target, the depth is smoothed by a separable bilateral filter
// whose screen radius follows depth, the fluid's thickness is summed at reduced resolution, and a
// composite pass shades the water from normals of the smoothed depth over the scene already drawn.
// Runs on the render thread, inside the Renderer's GL context.
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"

namespace rivulet {

struct ScreenFluidSettings {
    int filter_iterations = 1;   // bilateral passes (each one x and one y)
    float filter_radius = 2.0f;  // Gaussian sigma over the image, in particle radii at the pixel's depth
    float depth_sigma = 4.0f;    // Gaussian sigma over depth differences, in particle radii
    int max_filter_pixels = 16;  // the filter's half width never exceeds this
    int thickness_downsample = 2;
    // "" when valid, else the problem naming the option (--filter-iterations, ...).
    std::string validate() const;
};

// The passes' targets, for tests.
enum class ScreenFluidBuffer { kRawDepth, kSmoothedDepth, kThickness };

class ScreenFluidPass {
  public:
    // Allocates its targets for a width x height picture; throws std::runtime_error on a GL failure or
    // std::invalid_argument on bad settings.
    ScreenFluidPass(int width, int height, const ScreenFluidSettings& settings);
    ~ScreenFluidPass();
    ScreenFluidPass(const ScreenFluidPass&) = delete;
    ScreenFluidPass& operator=(const ScreenFluidPass&) = delete;

    void set_camera(const CameraDesc& camera, Vec3f light_dir);
    // Draws `particles` (spheres of `radius`) as water over the picture in the default framebuffer,
    // whose colour and depth are the scene behind. No particles: the picture is left as it is.
    void render(const ParticleSpritesView& particles, float radius);
    // Width x height floats (thickness: its reduced size, thickness_size()), rows bottom to top.
    void read(ScreenFluidBuffer which, std::span<float> out) const;
    int thickness_width() const;
    int thickness_height() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rivulet
