#pragma once
// Parameters of the density volume (Inácio et al., "Interactive Simulation and Visualization of Fluids
// with Surface Raycasting") and how the particle radius maps onto it:
//
//   h     = kernel_radii * radius         (default 4: two particle spacings, as the SPH scenes' support)
//   V_j   = (2 radius)^3                  (the volume of a particle of a lattice of spacing 2 radius, so
//                                          F is about 1 inside such a fluid)
//   iso   = calibrated_volume_iso(kernel_radii) when iso <= 0 (the default): the mean F one radius above
//           the top layer of a cubic lattice of spacing 2 radius, so a flat surface lies about one radius
//           outside the outermost particle centres, as with the other methods
//   voxel = h / 4 when voxel <= 0, grown where the particles would need more than max_dim cells per axis
#include <cstdint>
#include <string>

#include "jobs/density_splat.h"

namespace rivulet {

struct VolumeSettings {
    float radius = 0.02f;                 // particle radius, world units
    float kernel_radii = 4.0f;            // h / radius
    float voxel = 0;                      // world units; <= 0: automatic (see above)
    std::uint32_t max_dim = 128;          // cells per axis at most (the paper's 128^3 on a CPU)
    float iso = 0;                        // threshold on F; <= 0: calibrated_volume_iso(kernel_radii)
    std::uint32_t max_bricks = 1u << 18;  // stored bricks a frame may have (the atlas's capacity)

    float h() const { return kernel_radii * radius; }
    float particle_volume() const { return 8.0f * radius * radius * radius; }
    float iso_value() const;
    DensityGridParams grid_params() const;
    // Empty when valid, else what is wrong, naming the option.
    std::string validate() const;
};

// F one radius above the top layer of a semi-infinite cubic lattice of spacing 2 radius, averaged over
// 8 x 8 points of a lattice cell, for h = kernel_radii * radius (independent of the radius).
double calibrated_volume_iso(double kernel_radii);

}  // namespace rivulet
