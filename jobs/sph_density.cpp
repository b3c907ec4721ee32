#include "jobs/sph_density.h"

#include <cmath>

namespace rivulet {

float SphFluidParams::pressure(float rho) const {
    const float ratio = rho / rest_density;
    // Integer gamma (the usual 7) by repeated multiplication: exact order, no libm dependence.
    float powered = 1.0f;
    const float rounded = std::round(gamma);
    if (rounded == gamma && gamma >= 1.0f && gamma <= 16.0f) {
        for (int k = 0; k < static_cast<int>(rounded); ++k) powered *= ratio;
    } else {
        powered = std::pow(ratio, gamma);
    }
    const float p = stiffness * (powered - 1.0f);
    return p > 0.0f ? p : 0.0f;
}

void sph_density(const SphNeighbourhood& nb, const SphFluidParams& fluid, const SphWalls& walls,
                 std::size_t begin, std::size_t end, std::span<float> rho, std::span<float> p) {
    const float wall_scale = fluid.mass / (walls.spacing * walls.spacing);
    const SphKernels& k = fluid.kernels;
    const float h2 = k.h2;
    for (std::size_t i = begin; i < end; ++i) {
        const float xi = nb.x[i], yi = nb.y[i], zi = nb.z[i];
        float sum = 0.0f;
        sph_for_each_near(nb.grid, nb.cell_start, nb.key[i], [&](std::uint32_t j) {
            const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
            const float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < h2) {
                const float d = h2 - r2;
                sum += d * d * d;
            }
        });
        float density = fluid.mass * k.poly6 * sum;
        if (walls.enabled) {
            const float q[3] = {xi, yi, zi};
            float wall = 0.0f;
            for (int a = 0; a < 3; ++a) {
                const float lo = q[a] - walls.min[a], hi = walls.max[a] - q[a];
                if (lo < k.h) wall += sph_wall_terms(k, lo, walls.spacing).density;
                if (hi < k.h) wall += sph_wall_terms(k, hi, walls.spacing).density;
            }
            density += wall_scale * wall;
        }
        rho[i] = density;
        p[i] = fluid.pressure(density);
    }
}

}  // namespace rivulet
