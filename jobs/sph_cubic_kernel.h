#pragma once
// The cubic spline kernel (Monaghan 1992) with compact support h, 3D normalisation, as used by divergence-
// free SPH (Bender & Koschier 2015). With q = r / h:
//   W(r) = 8 / (pi h^3) (6 q^3 - 6 q^2 + 1)  for q <= 1/2
//          8 / (pi h^3) 2 (1 - q)^3          for 1/2 < q < 1, 0 beyond
// DFSPH takes density and its rate of change from one kernel (the rate is the gradient of that density),
// which Müller's pair of poly6 (density) and spiky (gradient) is not; the WCSPH solver keeps those.
#include <cmath>
#include <numbers>

#include "jobs/simd4.h"
#include "jobs/vector_lanes.h"

namespace rivulet {

struct SphCubicKernel {
    float h = 1, h2 = 1;
    float k = 0;  // 8 / (pi h^3)
    float l = 0;  // 48 / (pi h^3): dW/dq = l q (3 q - 2) or -l (1 - q)^2

    explicit SphCubicKernel(float support) : h(support), h2(support * support) {
        const double h3 = double(support) * support * support;
        k = static_cast<float>(8.0 / (std::numbers::pi * h3));
        l = static_cast<float>(48.0 / (std::numbers::pi * h3));
    }

    // W and dW/dq at distance r, 0 <= r < h (q = r / h): one sqrt serves both where a caller needs both.
    void at(float r, float& w_value, float& dwdq) const {
        const float q = r / h;
        if (q <= 0.5f) {
            w_value = k * (6.0f * q * q * q - 6.0f * q * q + 1.0f);
            dwdq = l * q * (3.0f * q - 2.0f);
        } else {
            const float t = 1.0f - q;
            w_value = k * 2.0f * t * t * t;
            dwdq = -l * t * t;
        }
    }
    // at() for four distances (each lane the same operations as the scalar call: the same bits).
    void at(simd::F4 r, simd::F4& w_value, simd::F4& dwdq) const {
        const simd::F4 q = r / simd::splat(h);
        const simd::F4 w_in = simd::splat(6.0f) * q * q * q - simd::splat(6.0f) * q * q + simd::splat(1.0f);
        const simd::F4 dw_in = simd::splat(l) * q * (simd::splat(3.0f) * q - simd::splat(2.0f));
        const simd::F4 t = simd::splat(1.0f) - q;
        const simd::F4 w_out = simd::splat(k * 2.0f) * t * t * t;
        const simd::F4 dw_out = simd::splat(-l) * t * t;
        const simd::F4 half = simd::splat(0.5f);
        w_value = simd::select_le(q, half, simd::splat(k) * w_in, w_out);
        dwdq = simd::select_le(q, half, dw_in, dw_out);
    }
    // at() for eight distances in GCC/Clang vector lanes (jobs/vector_lanes.h), by reference so no 32-byte
    // vector crosses a call of the baseline build; each lane the scalar call's bits.
    void at(const VectorLanes<8>::f& r, VectorLanes<8>::f& w_value, VectorLanes<8>::f& dwdq) const {
        using F = VectorLanes<8>::f;
        using I = VectorLanes<8>::i;
        const F q = r / h;
        const F t = 1.0f - q;
        const I inner = q <= 0.5f;
        const F w_in = k * (6.0f * q * q * q - 6.0f * q * q + 1.0f), w_out = (k * 2.0f) * t * t * t;
        const F dw_in = l * q * (3.0f * q - 2.0f), dw_out = -l * t * t;
        w_value =
            reinterpret_cast<F>((inner & reinterpret_cast<I>(w_in)) | (~inner & reinterpret_cast<I>(w_out)));
        dwdq = reinterpret_cast<F>((inner & reinterpret_cast<I>(dw_in)) |
                                   (~inner & reinterpret_cast<I>(dw_out)));
    }
    // W at squared distance r2.
    float w(float r2) const {
        if (r2 >= h2) return 0.0f;
        float w_value = 0.0f, dwdq = 0.0f;
        at(std::sqrt(r2), w_value, dwdq);
        return w_value;
    }
    // grad W(x) = grad_scale(r) * x for |x| = r (0 at r = 0 and from r = h on).
    float grad_scale(float r) const {
        if (r >= h || r <= 1e-9f * h) return 0.0f;
        float w_value = 0.0f, dwdq = 0.0f;
        at(r, w_value, dwdq);
        return dwdq / (h * r);
    }
};

}  // namespace rivulet
