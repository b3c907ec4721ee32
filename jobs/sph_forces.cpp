#include "jobs/sph_forces.h"

#include <cmath>

namespace rivulet {

float sph_forces(const SphForceInputs& in, const SphFluidParams& fluid, const SphWalls& walls,
                 std::size_t begin, std::size_t end, const SphAccelOut& out) {
    const SphKernels& k = fluid.kernels;
    const SphNeighbourhood& nb = in.nb;
    const float h = k.h, h2 = k.h2;
    const float m = fluid.mass;
    const bool tension = fluid.surface_tension;
    float max_a2 = 0.0f;
    // Pi_ij = -alpha c0 h vr / (rho_ij (r^2 + eps^2)) with rho_ij = (rho_i + rho_j) / 2.
    const float av_scale = -2.0f * fluid.alpha * fluid.sound_speed * h;
    const float eps2 = 0.01f * h2;
    for (std::size_t i = begin; i < end; ++i) {
        const float xi = nb.x[i], yi = nb.y[i], zi = nb.z[i];
        const float vxi = in.vx[i], vyi = in.vy[i], vzi = in.vz[i];
        const float pi = in.p[i];
        float fpx = 0, fpy = 0, fpz = 0;  // sum of (p_i + p_j) / rho_j * spiky (h - r)^2 / r * r_vec
        float fvx = 0, fvy = 0, fvz = 0;  // sum of (v_j - v_i) / rho_j * (h - r)
        float nx = 0, ny = 0, nz = 0, lap = 0;
        float avx = 0, avy = 0, avz = 0;  // sum of Pi_ij (h - r)^2 / r * r_vec
        const float rhoi = in.rho[i];
        const float qi[3] = {xi, yi, zi};
        const SphNearWalls near(walls, qi, h);
        const int images = (1 << near.count) - 1;
        // One neighbour (or wall image) at offset (dx, dy, dz) = x_i - x_j with velocity v_j.
        auto pair = [&](float dx, float dy, float dz, float r2, float vxj, float vyj, float vzj, float pj,
                        float rhoj) {
            const float inv_rho = 1.0f / rhoj;
            if (tension) {
                const float d = h2 - r2;
                const float g = d * d * inv_rho;
                nx += g * dx, ny += g * dy, nz += g * dz;
                lap += d * (3.0f * h2 - 7.0f * r2) * inv_rho;
            }
            if (r2 <= 0.0f) return;
            const float r = std::sqrt(r2);
            const float w = h - r;
            const float sp = (pi + pj) * inv_rho * w * w / r;
            fpx += sp * dx, fpy += sp * dy, fpz += sp * dz;
            const float vw = w * inv_rho;
            const float dvx = vxi - vxj, dvy = vyi - vyj, dvz = vzi - vzj;
            fvx -= dvx * vw, fvy -= dvy * vw, fvz -= dvz * vw;
            const float vr = dvx * dx + dvy * dy + dvz * dz;
            if (vr < 0.0f) {
                const float pij = av_scale * vr / ((r2 + eps2) * (rhoi + rhoj));
                const float s = pij * w * w / r;
                avx += s * dx, avy += s * dy, avz += s * dz;
            }
        };
        sph_for_each_near(nb.grid, nb.cell_start, nb.key[i], [&](std::uint32_t j) {
            const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
            const float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 >= h2) return;
            if (j != i) pair(dx, dy, dz, r2, in.vx[j], in.vy[j], in.vz[j], in.p[j], in.rho[j]);
            if (images == 0) return;
            const float qj[3] = {nb.x[j], nb.y[j], nb.z[j]};
            for (int mask = 1; mask <= images; ++mask) {
                float o[3];
                near.image(mask, qi, qj, o);
                const float s2 = o[0] * o[0] + o[1] * o[1] + o[2] * o[2];
                if (s2 >= h2) continue;
                float v[3] = {in.vx[j], in.vy[j], in.vz[j]};
                for (int t = 0; t < near.count; ++t) {
                    if (mask >> t & 1) v[near.axis[t]] = near.twice_v[t] - v[near.axis[t]];
                }
                pair(o[0], o[1], o[2], s2, v[0], v[1], v[2], in.p[j], in.rho[j]);
            }
        });
        // f_p = -m / 2 * spiky_grad * sum; spiky_grad < 0, so the pressure pushes i away from j.
        const float cp = -0.5f * m * k.spiky_grad;
        const float cv = fluid.viscosity * m * k.visc_lap;
        float fx = cp * fpx + cv * fvx, fy = cp * fpy + cv * fvy, fz = cp * fpz + cv * fvz;
        if (tension) {
            // The particle's own term of the colour field: grad is 0, lap is m / rho_i * lap W(0).
            lap += h2 * 3.0f * h2 / in.rho[i];
            const float gx = m * k.poly6_grad * nx, gy = m * k.poly6_grad * ny, gz = m * k.poly6_grad * nz;
            const float len = std::sqrt(gx * gx + gy * gy + gz * gz);
            if (len > fluid.tension_threshold) {
                const float s = -fluid.tension * m * k.poly6_lap * lap / len;
                fx += s * gx, fy += s * gy, fz += s * gz;
            }
        }
        const float inv_rho_i = 1.0f / rhoi;
        const float ca = -m * k.spiky_grad;
        const float ax = fx * inv_rho_i + ca * avx + fluid.gx;
        const float ay = fy * inv_rho_i + ca * avy + fluid.gy;
        const float az = fz * inv_rho_i + ca * avz + fluid.gz;
        out.ax[i] = ax, out.ay[i] = ay, out.az[i] = az;
        const float a2 = ax * ax + ay * ay + az * az;
        if (a2 > max_a2) max_a2 = a2;
    }
    return max_a2;
}

}  // namespace rivulet
