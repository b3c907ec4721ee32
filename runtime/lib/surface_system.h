#pragma once
// A surface method in the frame pipeline (scan, slices, and the methods to come): it adds its jobs to the
// frame graph after the simulation, owns its output in each of the two frame slots, and fills the render
// pass's view of a slot. The pipeline holds one and knows none by name; make_surface_system is the one
// place that does.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "jobs/particle_spans.h"
#include "runtime/lib/frame_graph.h"
#include "systems/render/frame_view.h"
#include "systems/render/screen_fluid.h"
#include "systems/render/volume_pass.h"
#include "systems/scan/scan_settings.h"
#include "systems/scenes/scene.h"
#include "systems/slices/slices_settings.h"
#include "systems/volume/volume_settings.h"

namespace rivulet {

class Renderer;

// kSprites draws a diffuse object's particles (Juckel & Beckhaus 2007) and is the only method of
// diffuse scenes.
// kHybrid: streams as oriented cylinders, the rest as marching slices (runtime/lib/hybrid_extractor.h).
enum class SurfaceMethod { kScan, kSlices, kScreen, kVolume, kSprites, kHybrid };
// "scan", "slices", "screen", "volume", "sprites" or "hybrid"; throws std::invalid_argument naming them
// otherwise.
SurfaceMethod parse_surface_method(const std::string& name);
const char* surface_method_name(SurfaceMethod m);

inline constexpr int kFrameSlots = 2;

// What a method made of one frame, for records and reports.
struct SurfaceStats {
    std::uint32_t groups = 0;    // scan: cylinders drawn; slices: non-empty blocks; volume: bricks stored
    std::uint32_t isolated = 0;  // scan: particles drawn as spheres
    std::uint64_t triangles = 0;
    std::uint32_t pool_exhausted = 0;  // scan: entries left isolated because every cylinder was in use
};

class SurfaceSystem {
  public:
    virtual ~SurfaceSystem() = default;
    virtual SurfaceMethod method() const = 0;
    // Adds the method's jobs after `after`; returns the job that ends the surface. `positions` and `slot`
    // are asked when each job runs: the particles of the frame and the slot to write.
    virtual FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                       std::function<int()> slot, FrameGraph::JobId after) = 0;
    // The particles' own volumes where the scene's simulation gives them (SPH: mass / density), asked when
    // each job runs; set before add_jobs. Only the density volume uses them (its V_j); the rest ignore them.
    virtual void use_particle_volumes(std::function<ParticleVolumes()>) {}
    // Of the frame in `slot`; read once the graph that filled it has finished and before it runs again
    // (a method may keep per-frame counts of its last frame only).
    virtual SurfaceStats stats(int slot) const = 0;
    // A hash of the slot's surface buffers (replay and determinism tests compare these).
    virtual std::uint64_t output_hash(int slot) const = 0;
    // The render pass: GL buffers sized once for the method's largest output, then a slot's view.
    virtual void prepare_renderer(Renderer& renderer) const = 0;
    virtual void fill_view(int slot, FrameView& view) const = 0;
};

struct SurfaceMethodSettings {
    SurfaceMethod method = SurfaceMethod::kScan;
    ScanSettings scan;      // radius and V range are taken from the scene
    SlicesSettings slices;  // radius is taken from the scene
    ScreenFluidSettings screen;
    VolumeSettings volume;  // radius is taken from the scene
    VolumeRaycastSettings raycast;
};

class SceneSimulation;

// Sized for the scene's max_particles and `threads` workers; throws std::invalid_argument on bad settings,
// and when the method does not fit the scene: a diffuse scene is drawn with sprites, and sprites draw
// only a diffuse scene (`sim` then names its simulation, which the sprites read each frame).
std::unique_ptr<SurfaceSystem> make_surface_system(const SurfaceMethodSettings& config,
                                                   const SceneDesc& scene, std::size_t threads,
                                                   const SceneSimulation* sim = nullptr);

}  // namespace rivulet
