#include "jobs/cross_section.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "jobs/cpu_dispatch.h"

namespace rivulet {

namespace {

RIVULET_INLINE void circle_maxima_body(CirclesView c, AngleTable a, std::span<float> r) {
    const std::size_t u = r.size();
    std::fill(r.begin(), r.end(), 0.0f);
    for (std::size_t i = 0; i < c.size(); ++i) {
        const float cx = c.cx[i], cz = c.cz[i];
        const float q = c.rho[i] * c.rho[i] - (cx * cx + cz * cz);
        for (std::size_t k = 0; k < u; ++k) {
            const float b = cx * a.cos_t[k] + cz * a.sin_t[k];
            const float disc = b * b + q;
            const float t = b + std::sqrt(std::max(disc, 0.0f));
            r[k] = std::max(r[k], t);
        }
    }
}

// U square roots per circle: twice the lanes halve the time on this, the deformation's hottest loop.
RIVULET_AVX2 void circle_maxima_avx2(CirclesView c, AngleTable a, std::span<float> r) {
    circle_maxima_body(c, a, r);
}

}  // namespace

void fill_angle_table(std::span<float> cos_t, std::span<float> sin_t) {
    const std::size_t u = cos_t.size();
    for (std::size_t k = 0; k < u; ++k) {
        const double theta = 2.0 * std::numbers::pi * double(k) / double(u);
        cos_t[k] = static_cast<float>(std::cos(theta));
        sin_t[k] = static_cast<float>(std::sin(theta));
    }
}

void circle_maxima(CirclesView c, AngleTable a, std::span<float> r) {
    if (cpu_has_avx2())
        circle_maxima_avx2(c, a, r);
    else
        circle_maxima_body(c, a, r);
}

namespace {

// r[k * Lanes + j] is ring j's value at angle k: the lanes of one angle are independent rings, so each
// step is a few full-width vector operations with no remainder, and every lane computes exactly what a
// lone ring would.
template <std::size_t Lanes>
RIVULET_INLINE void smooth_cyclic_body(std::span<float> r, std::size_t u, int iterations,
                                       std::span<float> tmp) {
    if (u < 3) return;
    // Ping-pong between r and tmp; the wrap-around ends are done apart so the middle loop vectorizes.
    float* src = r.data();
    float* dst = tmp.data();
    const auto step = [](float* d, const float* before, const float* at, const float* after) {
        for (std::size_t j = 0; j < Lanes; ++j) d[j] = 0.25f * before[j] + 0.5f * at[j] + 0.25f * after[j];
    };
    for (int it = 0; it < iterations; ++it) {
        step(dst, src + (u - 1) * Lanes, src, src + Lanes);
        for (std::size_t k = 1; k + 1 < u; ++k)
            step(dst + k * Lanes, src + (k - 1) * Lanes, src + k * Lanes, src + (k + 1) * Lanes);
        step(dst + (u - 1) * Lanes, src + (u - 2) * Lanes, src + (u - 1) * Lanes, src);
        std::swap(src, dst);
    }
    if (src != r.data()) std::copy(src, src + u * Lanes, r.data());
}

RIVULET_AVX2 void smooth_cyclic_avx2(std::span<float> r, int iterations, std::span<float> tmp) {
    smooth_cyclic_body<1>(r, r.size(), iterations, tmp);
}

RIVULET_AVX2 void smooth_cyclic_rings_avx2(std::span<float> r, std::size_t u, int iterations,
                                           std::span<float> tmp) {
    smooth_cyclic_body<kSmoothLanes>(r, u, iterations, tmp);
}

}  // namespace

void smooth_cyclic(std::span<float> r, int iterations, std::span<float> tmp) {
    if (cpu_has_avx2())
        smooth_cyclic_avx2(r, iterations, tmp);
    else
        smooth_cyclic_body<1>(r, r.size(), iterations, tmp);
}

void smooth_cyclic_rings(std::span<float> r, std::size_t u, int iterations, std::span<float> tmp) {
    if (cpu_has_avx2())
        smooth_cyclic_rings_avx2(r, u, iterations, tmp);
    else
        smooth_cyclic_body<kSmoothLanes>(r, u, iterations, tmp);
}

void gaussian_blend(CirclesView c, AngleTable a, float tension, std::span<float> r, std::span<float> alpha) {
    const std::size_t u = r.size();
    std::fill(r.begin(), r.end(), 0.0f);
    std::fill(alpha.begin(), alpha.begin() + static_cast<std::ptrdiff_t>(u), 0.0f);
    for (std::size_t i = 0; i < c.size(); ++i) {
        const float dist = std::sqrt(c.cx[i] * c.cx[i] + c.cz[i] * c.cz[i]);
        const float radius = std::max(c.rho[i], 1e-6f);
        const float height = dist + c.rho[i];
        const float w = tension * dist * dist / radius;
        const float dir_x = dist > 0 ? c.cx[i] / dist : 0.0f, dir_z = dist > 0 ? c.cz[i] / dist : 0.0f;
        for (std::size_t k = 0; k < u; ++k) {
            const float g = std::exp(-w * (1.0f - (dir_x * a.cos_t[k] + dir_z * a.sin_t[k])));
            const float gd = g * height;
            float blend = alpha[k];
            if (gd > r[k]) {
                const float b = (gd - r[k]) / gd;
                blend = alpha[k] * (1.0f - b) + (1.0f - g) * b;
            }
            r[k] = r[k] * blend + gd * (1.0f - blend);
            alpha[k] = std::min(alpha[k] + g, 1.0f);
        }
    }
}

}  // namespace rivulet
