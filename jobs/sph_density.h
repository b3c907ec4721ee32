#pragma once
// SPH density and pressure (Inácio et al. 2010 §III, Müller et al. 2003 eq. 3):
// rho_i = sum_j m W_poly6(x_i - x_j), the particle itself included; p_i from the Tait equation of state
// p = B ((rho / rho0)^gamma - 1), clamped at 0. Gathers over the sorted particles of the 27 cells around
// each particle in a fixed order, so a particle's result does not depend on how the range is split.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/sph_grid.h"
#include "jobs/sph_kernels.h"

namespace rivulet {

struct SphFluidParams {
    SphKernels kernels{1.0f};
    float mass = 1;
    float rest_density = 1000;
    float stiffness = 0;  // Tait B = rho0 c0^2 / gamma
    float gamma = 7;
    float viscosity = 0;  // mu
    float alpha = 0;      // Monaghan artificial viscosity (approaching pairs only)
    float sound_speed = 0;
    bool surface_tension = false;
    float tension = 0;            // sigma
    float tension_threshold = 0;  // |n| threshold
    float gx = 0, gy = 0, gz = 0;

    float pressure(float rho) const;
};

// The tank walls as seen by the fluid: mirror particles. For a particle within h of a face, every
// neighbour j has an image reflected across that face (and across every pair and triple of near faces,
// for edges and corners), carrying j's density and pressure, and j's velocity with the component normal
// to the face reflected about the wall's velocity (free slip). The images continue the fluid beyond the
// wall, so density, pressure gradient (normal and tangential) and viscosity see a full neighbourhood; an
// image lies within h of i only if j does, so the same 27-cell search finds them. `enabled` false turns
// the walls off (the hard constraint of sph_integrate still holds the fluid in).
struct SphWalls {
    bool enabled = false;
    float min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
    float velocity[3] = {0, 0, 0};  // of the walls (the moving container)
};

// The faces within h of a point: up to one per axis (the tank is wider than 2h).
struct SphNearWalls {
    int count = 0;
    int axis[3] = {0, 0, 0};
    float twice[3] = {0, 0, 0};    // 2 * face coordinate: image coordinate = twice - coordinate
    float twice_v[3] = {0, 0, 0};  // 2 * wall velocity along the axis
    SphNearWalls(const SphWalls& w, const float q[3], float h) {
        if (!w.enabled) return;
        for (int a = 0; a < 3; ++a) {
            if (q[a] - w.min[a] < h) {
                axis[count] = a, twice[count] = 2.0f * w.min[a], twice_v[count] = 2.0f * w.velocity[a],
                ++count;
            } else if (w.max[a] - q[a] < h) {
                axis[count] = a, twice[count] = 2.0f * w.max[a], twice_v[count] = 2.0f * w.velocity[a],
                ++count;
            }
        }
    }
    // Offset i - image(j) for image `mask` (bit t: reflected across face t).
    void image(int mask, const float qi[3], const float qj[3], float d[3]) const {
        for (int a = 0; a < 3; ++a) d[a] = qi[a] - qj[a];
        for (int t = 0; t < count; ++t) {
            if (mask >> t & 1) d[axis[t]] = qi[axis[t]] - (twice[t] - qj[axis[t]]);
        }
    }
};

// Sorted particle positions and their cells (sph_grid_scatter_chunk output) with the grid's cell ranges.
struct SphNeighbourhood {
    SphGrid grid;
    std::span<const std::uint32_t> cell_start;
    std::span<const std::uint32_t> key;
    std::span<const float> x, y, z;
};

// Writes rho[i] and p[i] for sorted particles [begin, end), with the wall images of SphWalls.
void sph_density(const SphNeighbourhood& nb, const SphFluidParams& fluid, const SphWalls& walls,
                 std::size_t begin, std::size_t end, std::span<float> rho, std::span<float> p);

}  // namespace rivulet
