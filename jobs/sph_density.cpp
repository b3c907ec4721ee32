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
    const SphKernels& k = fluid.kernels;
    const float h2 = k.h2;
    for (std::size_t i = begin; i < end; ++i) {
        const float xi = nb.x[i], yi = nb.y[i], zi = nb.z[i];
        const float qi[3] = {xi, yi, zi};
        const SphNearWalls near(walls, qi, k.h);
        const int images = (1 << near.count) - 1;
        float sum = 0.0f;
        sph_for_each_near(nb.grid, nb.cell_start, nb.key[i], [&](std::uint32_t j) {
            const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
            const float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 >= h2) return;
            float d = h2 - r2;
            sum += d * d * d;
            const float qj[3] = {nb.x[j], nb.y[j], nb.z[j]};
            for (int mask = 1; mask <= images; ++mask) {
                float o[3];
                near.image(mask, qi, qj, o);
                const float s2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
                if (s2 >= h2) continue;
                d = h2 - s2;
                sum += d * d * d;
            }
        });
        const float density = fluid.mass * k.poly6 * sum;
        rho[i] = density;
        p[i] = fluid.pressure(density);
    }
}

}  // namespace rivulet
