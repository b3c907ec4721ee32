#include "runtime/lib/surface_system.h"

#include <stdexcept>

#include "runtime/lib/hybrid_surface.h"
#include "runtime/lib/scan_surface.h"
#include "runtime/lib/scene_simulation.h"
#include "runtime/lib/screen_surface.h"
#include "runtime/lib/slices_surface.h"
#include "runtime/lib/sprites_surface.h"
#include "runtime/lib/volume_surface.h"

namespace rivulet {

SurfaceMethod parse_surface_method(const std::string& name) {
    if (name == "scan") return SurfaceMethod::kScan;
    if (name == "slices") return SurfaceMethod::kSlices;
    if (name == "screen") return SurfaceMethod::kScreen;
    if (name == "volume") return SurfaceMethod::kVolume;
    if (name == "sprites") return SurfaceMethod::kSprites;
    if (name == "hybrid") return SurfaceMethod::kHybrid;
    throw std::invalid_argument("unknown surface method '" + name +
                                "': use 'scan', 'slices', 'screen', 'volume', 'hybrid' or (diffuse scenes) "
                                "'sprites'");
}

const char* surface_method_name(SurfaceMethod m) {
    switch (m) {
        case SurfaceMethod::kScan:
            return "scan";
        case SurfaceMethod::kSlices:
            return "slices";
        case SurfaceMethod::kScreen:
            return "screen";
        case SurfaceMethod::kVolume:
            return "volume";
        case SurfaceMethod::kSprites:
            return "sprites";
        case SurfaceMethod::kHybrid:
            return "hybrid";
    }
    return "?";
}

std::unique_ptr<SurfaceSystem> make_surface_system(const SurfaceMethodSettings& config,
                                                   const SceneDesc& scene, std::size_t threads,
                                                   const SceneSimulation* sim) {
    const bool diffuse = scene.simulation == SimulationKind::kDiffuse;
    if (diffuse != (config.method == SurfaceMethod::kSprites))
        throw std::invalid_argument(
            diffuse ? "scene '" + scene.name + "' is a diffuse object: it is drawn with --method sprites"
                    : std::string("--method sprites draws diffuse-object scenes only (ghost, dissolve, fire, "
                                  "bunny, or a scene file with \"simulation\": \"diffuse\")"));
    switch (config.method) {
        case SurfaceMethod::kScan: {
            ScanSettings s = config.scan;
            s.radius = scene.particle_radius;
            s.v_top = scene.v_max;
            s.v_bottom = scene.v_min;
            return std::make_unique<ScanSurface>(s, scene.max_particles);
        }
        case SurfaceMethod::kHybrid: {
            ScanSettings scan = config.scan;
            scan.radius = scene.particle_radius;
            scan.v_top = scene.v_max;
            scan.v_bottom = scene.v_min;
            SlicesSettings slices = config.slices;
            slices.radius = scene.particle_radius;
            return std::make_unique<HybridSurface>(scan, slices, scene.max_particles, threads);
        }
        case SurfaceMethod::kSlices: {
            SlicesSettings s = config.slices;
            s.radius = scene.particle_radius;
            return std::make_unique<SlicesSurface>(s, scene.max_particles, threads);
        }
        case SurfaceMethod::kScreen:
            return std::make_unique<ScreenSurface>(config.screen, scene.max_particles, scene.particle_radius);
        case SurfaceMethod::kVolume: {
            VolumeSettings s = config.volume;
            s.radius = scene.particle_radius;
            return std::make_unique<VolumeSurface>(s, config.raycast, scene.max_particles);
        }
        case SurfaceMethod::kSprites:
            if (!sim || !sim->diffuse())
                throw std::invalid_argument("sprites need the scene's diffuse simulation");
            return std::make_unique<SpritesSurface>(scene, [sim] {
                return SpritesSurface::SpriteSource{sim->diffuse()->sprites(), sim->diffuse()->depth_keys()};
            });
    }
    throw std::invalid_argument("unknown surface method");
}

}  // namespace rivulet
