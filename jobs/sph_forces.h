#pragma once
// SPH accelerations (Inácio et al. 2010 §III eq. 2, Müller et al. 2003 §3-4), per sorted particle i:
//   pressure   f_p = -sum_j m (p_i + p_j) / (2 rho_j) grad W_spiky(x_i - x_j)
//   viscosity  f_v = mu sum_j m (v_j - v_i) / rho_j lap W_visc(|x_i - x_j|)
//   artificial viscosity (Monaghan 1992), only between approaching particles (v_ij . r_ij < 0):
//              a_av = -sum_j m Pi_ij grad W_spiky, Pi_ij = -alpha c0 h v_ij . r_ij / (rho_ij (r^2 + 0.01
//              h^2)), rho_ij = (rho_i + rho_j) / 2; it damps the acoustic noise of the weakly compressible
//              fluid
//   tension    f_s = -sigma lap(c) n / |n| where |n| > threshold, n = sum_j m / rho_j grad W_poly6,
//              lap(c) = sum_j m / rho_j lap W_poly6 (colour field, optional)
//   a_i = (f_p + f_v + f_s) / rho_i + a_av + g ; the sums include the tank's mirror images
//   of the neighbours (SphWalls)
// Gathers in the fixed neighbour order of sph_for_each_near, so results do not depend on the split.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/sph_density.h"

namespace rivulet {

struct SphForceInputs {
    SphNeighbourhood nb;
    std::span<const float> vx, vy, vz;
    std::span<const float> rho, p;
};

struct SphAccelOut {
    std::span<float> ax, ay, az;
};

// Writes accelerations of sorted particles [begin, end); returns the largest |a|^2 among them.
float sph_forces(const SphForceInputs& in, const SphFluidParams& fluid, const SphWalls& walls,
                 std::size_t begin, std::size_t end, const SphAccelOut& out);

}  // namespace rivulet
