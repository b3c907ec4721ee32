#pragma once
// Headless OpenGL 4.5 core renderer on OSMesa (llvmpipe). The thread that constructs it owns the context
// and is the only one that may call render(). Setup failures throw std::runtime_error with a clear text.
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "jobs/cylinder_layout.h"
#include "systems/render/environment_map.h"
#include "systems/render/frame_view.h"
#include "systems/render/screen_fluid.h"
#include "systems/render/volume_pass.h"
#include "systems/render/water_backdrop.h"
#include "systems/scenes/scene.h"

namespace rivulet {

// The most moving colliders a scene may have (DiffuseDesc::colliders).
inline constexpr std::size_t kMaxMovers = 8;

struct RenderSettings {
    int width = 1280;
    int height = 720;
};

// Milliseconds of each part of the last render() with Renderer::set_time_passes(true) (GL finished after
// each; else zeros). `scene`: ground, solids, sky and the tank's back glass; `water_thickness`: the scene
// copy and the mesh methods' thickness; `water`: the pool's and the meshes' lit water; `screen`: the
// screen-space fluid pass (its own parts: ScreenFluidPass::timings); `finish`: the front glass and the
// wait for the picture; `diffuse`: the diffuse objects' sprites, drawn between those two;
// `volume_upload`: the density volume's bricks into GL; `volume`: its raycast (VolumePass::timings).
struct RenderTimings {
    double upload = 0, shadow = 0, scene = 0, water_thickness = 0, water = 0, screen = 0, finish = 0;
    double diffuse = 0;
    double volume_upload = 0, volume = 0;
};

class Renderer {
  public:
    explicit Renderer(const RenderSettings& settings);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Static content: camera, key light and its shadow map's fit, environment (made, or loaded from the
    // scene's six faces: throws std::runtime_error naming a face file that is missing, not a PNG or of the
    // wrong size), water colour, ground plane, colliders, pool grid size, an SPH scene's tank. Call once
    // per scene.
    void set_scene(const SceneDesc& scene);
    // Where the SPH tank is drawn, from its rest pose (FrameInputs::container_offset): call before
    // render() in scenes whose container moves. Until called the tank stays at rest.
    void set_container_offset(Vec3f offset);
    // Where a diffuse scene's colliders are this frame, in the scene's order (at most kMaxMovers).
    void set_mover_offsets(std::span<const Vec3f> centres);
    // Builds the shared cylinder index buffer (sent to GL once) and a vertex buffer for `max_cylinders`.
    void set_cylinder_pool(const CylinderLayout& layout, std::uint32_t max_cylinders);

    // Sets up the screen-space fluid pass that draws a frame's sprites (once per run).
    void set_screen_fluid(const ScreenFluidSettings& settings);
    // Sets up the pass that draws frames' diffuse-object sprites (FrameView::diffuse), with room for
    // `max_sprites` a frame. Once per run; a later call with a different size replaces it.
    void set_diffuse_sprites(std::uint32_t max_sprites);
    // Sets up the pass that raycasts a frame's density volume (FrameView::volume; once per run).
    void set_volume_raycast(const VolumeRaycastSettings& settings);

    // Uploads only the changed ranges of `frame` (rings [vmin, vmax] per group), draws, and finishes.
    void render(const FrameView& frame);
    // The screen-space fluid pass of the last frame (tests); throws when there is none.
    const ScreenFluidPass& screen_fluid() const;
    // The density volume's pass (tests); throws when there is none.
    const VolumePass& volume_pass() const;
    // Benchmarks: finish GL after each part of render() and time it (slows the frame).
    void set_time_passes(bool on);
    const RenderTimings& timings() const;
    // The mesh methods' water targets: the last frame's fluid thickness (tests).
    const WaterBackdrop& water_backdrop() const;
    // The cube map behind the scene and in its reflections (tests read its faces back).
    const EnvironmentMap& environment() const;

    int width() const;
    int height() const;
    // The last rendered picture, RGBA8, rows top to bottom; `out` holds width*height*4 bytes.
    void read_rgba(std::span<std::uint8_t> out) const;
    std::string gl_version() const;
    std::string gl_renderer() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rivulet
