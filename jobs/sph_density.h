#pragma once
// SPH density and pressure (seed 002 §III, Müller et al. 2003 eq. 3): rho_i = sum_j m W_poly6(x_i - x_j),
// the particle itself included; p_i from the Tait equation of state p = B ((rho / rho0)^gamma - 1),
// clamped at 0. Gathers over the sorted particles of the 27 cells around each particle in a fixed order,
// so a particle's result does not depend on how the range is split.
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

// The tank walls as seen by the fluid: the lattice of particles continued beyond each face (layers at
// 1/2, 3/2, ... spacings outside it, as the fluid's own lattice would put them), each layer taken as a
// continuous sheet of areal density 1/spacing^2. A wall at distance s adds to a particle's density
//   m / d^2 * sum_layers poly6 * pi (h^2 - delta^2)^4 / 4                  (delta = s + (k + 1/2) d)
// and, with the particle's own pressure mirrored onto it, the acceleration along the wall's inward normal
//   m p_i / rho_i^2 * sum_layers 45 / (pi h^6) * 2 pi delta (h - delta)^3 / (3 d^2)
// (the in-plane parts cancel). The artificial viscosity acts the same way against a particle approaching a
// wall: Pi = -alpha c0 h v_n delta / (rho_i (delta^2 + 0.01 h^2)) in place of p_i / rho_i^2. Faces are the
// tank box's; `enabled` false turns the walls off.
struct SphWalls {
    bool enabled = false;
    float min[3] = {0, 0, 0}, max[3] = {0, 0, 0};
    float spacing = 1;
    float velocity[3] = {0, 0, 0};  // of the walls (the moving container)
};

// Sum over the wall layers within h of a particle at distance s from a face: density (first) and the
// normal pressure-gradient factor (second), both without the m / d^2 factor.
struct SphWallTerms {
    float density = 0, push = 0, damp = 0;  // damp: sum of push terms / (delta^2 + 0.01 h^2) * delta
};
inline SphWallTerms sph_wall_terms(const SphKernels& k, float s, float d) {
    SphWallTerms t;
    if (s < 0.0f) s = 0.0f;
    for (float delta = s + 0.5f * d; delta < k.h; delta += d) {
        const float q = k.h2 - delta * delta;
        t.density += k.poly6 * 0.78539816f * q * q * q * q;  // pi / 4
        const float w = k.h - delta;
        const float push = -k.spiky_grad * 2.0943951f * delta * w * w * w;  // 2 pi / 3
        t.push += push;
        t.damp += push * delta / (delta * delta + 0.01f * k.h2);
    }
    return t;
}

// Sorted particle positions and their cells (sph_grid_scatter_chunk output) with the grid's cell ranges.
struct SphNeighbourhood {
    SphGrid grid;
    std::span<const std::uint32_t> cell_start;
    std::span<const std::uint32_t> key;
    std::span<const float> x, y, z;
};

// Writes rho[i] and p[i] for sorted particles [begin, end).
void sph_density(const SphNeighbourhood& nb, const SphFluidParams& fluid, const SphWalls& walls,
                 std::size_t begin, std::size_t end, std::span<float> rho, std::span<float> p);

}  // namespace rivulet
