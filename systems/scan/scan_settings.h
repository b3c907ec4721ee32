#pragma once
#include <cstdint>
#include <span>
#include <string>

#include "jobs/cross_section.h"

namespace rivulet {

// Where cylinders point: `kVertical` bins every group along the V axis (the paper); `kPath` orients each
// along its stream's path (OrientedScan), so arcs and hoses stay round where they run sideways.
enum class CylinderAxis : std::uint8_t { kVertical, kPath };

// Parameters of sphere scan conversion (Hoetzlein & Höllerer 2009). Defaults follow the paper: U = 20,
// V = 120, 150 cylinders, eps = 1.75 sphere diameters, circle maxima with 10 smoothing iterations.
struct ScanSettings {
    std::uint32_t u = 20;
    std::uint32_t v = 120;
    std::uint32_t max_groups = 150;
    float radius = 0.02f;  // particle (sphere) radius, world units
    float epsilon = 0;     // grouping distance; <= 0 means epsilon_diameters * 2 * radius
    float epsilon_diameters = 1.75f;
    CrossSectionParams section;
    float v_top = 3;     // y of the first cross-section plane
    float v_bottom = 0;  // y of the last cross-section plane
    CylinderAxis axis = CylinderAxis::kPath;

    float grouping_distance() const { return epsilon > 0 ? epsilon : epsilon_diameters * 2.0f * radius; }
    // For particles meshed on their own (no scene to take the range from): planes from half a radius
    // inside the extreme spheres, so every sphere is cut at least once. `y` is not empty.
    void fit_v_range(std::span<const float> y);
    // Empty when valid, else what is wrong (for a clear error message).
    std::string validate() const;
};

}  // namespace rivulet
