#include "runtime/lib/surface_system.h"

#include <stdexcept>

#include "runtime/lib/scan_surface.h"
#include "runtime/lib/screen_surface.h"
#include "runtime/lib/slices_surface.h"

namespace rivulet {

SurfaceMethod parse_surface_method(const std::string& name) {
    if (name == "scan") return SurfaceMethod::kScan;
    if (name == "slices") return SurfaceMethod::kSlices;
    if (name == "screen") return SurfaceMethod::kScreen;
    throw std::invalid_argument("unknown surface method '" + name + "': use 'scan', 'slices' or 'screen'");
}

const char* surface_method_name(SurfaceMethod m) {
    switch (m) {
        case SurfaceMethod::kScan:
            return "scan";
        case SurfaceMethod::kSlices:
            return "slices";
        case SurfaceMethod::kScreen:
            return "screen";
    }
    return "?";
}

std::unique_ptr<SurfaceSystem> make_surface_system(const SurfaceConfig& config, const SceneDesc& scene,
                                                   std::size_t threads) {
    switch (config.method) {
        case SurfaceMethod::kScan: {
            ScanSettings s = config.scan;
            s.radius = scene.particle_radius;
            s.v_top = scene.v_max;
            s.v_bottom = scene.v_min;
            return std::make_unique<ScanSurface>(s, scene.max_particles);
        }
        case SurfaceMethod::kSlices: {
            SlicesSettings s = config.slices;
            s.radius = scene.particle_radius;
            return std::make_unique<SlicesSurface>(s, scene.max_particles, threads);
        }
        case SurfaceMethod::kScreen:
            return std::make_unique<ScreenSurface>(config.screen, scene.max_particles, scene.particle_radius);
    }
    throw std::invalid_argument("unknown surface method");
}

}  // namespace rivulet
