#pragma once
// The density volume's iso-surface, raycast per pixel (Inácio, Nobrega, Carvalho & von Wangenheim,
// "Interactive Simulation and Visualization of Fluids with Surface Raycasting"), with the empty-space
// skipping and early ray termination of Krüger & Westermann, "Acceleration Techniques for GPU-based
// Volume Rendering" (2003): rays walk the sparse bricks and march only those that can hold the surface.
// The hit is shaded with the water every method shares (shaders::kWaterShading) over the scene already
// drawn. Runs on the render thread, inside the Renderer's GL context.
//
// A frame: the bricks go into a 3D atlas texture and a per-brick table (upload); the faces around the
// blocks of 2^3 cells that can hold the surface are rasterised into a per-pixel span and a depth mask;
// the rays run only where that mask is set, over a copy of the scene, and the picture's water is copied
// back. Like the screen-space composite, the water leaves the scene's depth buffer as it was.
#include <memory>
#include <span>
#include <string>

#include "jobs/density_volume.h"
#include "jobs/vec3.h"
#include "systems/scenes/scene.h"
#include "systems/scenes/scene_look.h"

namespace rivulet {

struct VolumeRaycastSettings {
    float step = 0.5f;         // march step inside a brick that may hold the surface, in voxels, (0, 0.5]
    int refine = 6;            // bisection steps at a crossing, [0, kMaxRefine]
    bool time_passes = false;  // finish GL after each part and time it (benchmarks; slows the frame)
    static constexpr int kMaxRefine = 16;
    // "" when valid, else the problem naming the setting.
    std::string validate() const;
};

// Milliseconds of the last frame's parts (with VolumeRaycastSettings::time_passes; else zeros). `upload`:
// the brick table, the shell's faces and the atlas into GL; `raycast`: the scene copy, the shell, the rays
// and the water's copy back into the picture.
struct VolumeTimings {
    double upload = 0, raycast = 0;
};

// The pass's targets, for tests. kDepth: eye-space depth of the hit along the view axis (as
// ScreenFluidBuffer::kSmoothedDepth), 0 where no ray meets the surface; kThickness: the length of water
// along the pixel's ray behind the hit, world units.
enum class VolumeBuffer { kDepth, kThickness };

class VolumePass {
  public:
    // Allocates its targets for a width x height picture; throws std::runtime_error on a GL failure or
    // std::invalid_argument on bad settings.
    VolumePass(int width, int height, const VolumeRaycastSettings& settings);
    ~VolumePass();
    VolumePass(const VolumePass&) = delete;
    VolumePass& operator=(const VolumePass&) = delete;

    void set_camera(const CameraDesc& camera, Vec3f light_dir);
    void set_water(const WaterLook& water);
    // A GL cube-map texture the water reflects (the Renderer's environment), read at `reflection_lod`
    // as the lit water reads it; 0: the analytic sky.
    void set_environment(unsigned cube_map_texture, float reflection_lod = 0.0f);
    // The fluid is drawn inside this world box only (an SPH tank's glass); by default everywhere.
    void set_clip(Vec3f lo, Vec3f hi);
    void clear_clip();

    // upload() then draw(). A volume with no stored bricks draws nothing.
    void render(const DensityVolumeView& volume);
    // Copies the frame's bricks into GL. Throws std::out_of_range when the view is inconsistent (spans of
    // the wrong size, a slot outside the stored bricks) and std::runtime_error when the atlas exceeds
    // what GL can hold.
    void upload(const DensityVolumeView& volume);
    // Draws the last upload as water over the picture in the default framebuffer, whose colour and
    // depth are the scene behind.
    void draw();

    // Width x height floats, rows bottom to top.
    void read(VolumeBuffer which, std::span<float> out) const;
    const VolumeTimings& timings() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rivulet
