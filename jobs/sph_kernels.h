#pragma once
// SPH smoothing kernels of Müller, Charypar & Gross 2003 (Inácio et al. 2010 §III), 3D normalisations.
// h is the support radius: every kernel is zero for r >= h.
//   poly6      W(r)      = 315 / (64 pi h^9) (h^2 - r^2)^3            density, colour field
//   spiky      grad W(r) = -45 / (pi h^6) (h - r)^2 r/|r|             pressure force
//   viscosity  lap W(r)  =  45 / (pi h^6) (h - r)                     viscosity force
// The kernels take squared distances or distances as the callers have them, so no loop pays a sqrt it
// does not need.
#include <numbers>

namespace rivulet {

struct SphKernels {
    float h = 1, h2 = 1;
    float poly6 = 0;       // 315 / (64 pi h^9)
    float poly6_grad = 0;  // -945 / (32 pi h^9): grad W_poly6 = poly6_grad (h^2 - r^2)^2 r
    float poly6_lap = 0;   // -945 / (32 pi h^9): lap W_poly6 = poly6_lap (h^2 - r^2)(3 h^2 - 7 r^2)
    float spiky_grad = 0;  // -45 / (pi h^6)
    float visc_lap = 0;    // 45 / (pi h^6)

    explicit SphKernels(float support) : h(support), h2(support * support) {
        const double pi = std::numbers::pi;
        const double hd = support;
        const double h6 = hd * hd * hd * hd * hd * hd;
        const double h9 = h6 * hd * hd * hd;
        poly6 = static_cast<float>(315.0 / (64.0 * pi * h9));
        poly6_grad = static_cast<float>(-945.0 / (32.0 * pi * h9));
        poly6_lap = static_cast<float>(-945.0 / (32.0 * pi * h9));
        spiky_grad = static_cast<float>(-45.0 / (pi * h6));
        visc_lap = static_cast<float>(45.0 / (pi * h6));
    }

    // W_poly6 at squared distance r2.
    float w_poly6(float r2) const {
        if (r2 >= h2) return 0.0f;
        const float d = h2 - r2;
        return poly6 * d * d * d;
    }
    // grad W_poly6 = w_poly6_grad_scale(r2) * r_vec.
    float poly6_grad_scale(float r2) const {
        if (r2 >= h2) return 0.0f;
        const float d = h2 - r2;
        return poly6_grad * d * d;
    }
    float lap_poly6(float r2) const {
        if (r2 >= h2) return 0.0f;
        return poly6_lap * (h2 - r2) * (3.0f * h2 - 7.0f * r2);
    }
    // grad W_spiky = spiky_grad_scale(r) * r_vec, for 0 < r < h (r_vec / r is the direction).
    float spiky_grad_scale(float r) const {
        if (r >= h || r <= 0.0f) return 0.0f;
        const float d = h - r;
        return spiky_grad * d * d / r;
    }
    // W_spiky itself (15 / (pi h^6) (h - r)^3), for the normalisation test.
    float w_spiky(float r) const {
        if (r >= h) return 0.0f;
        const float d = h - r;
        return -spiky_grad / 3.0f * d * d * d;
    }
    // W_viscosity itself: 15 / (2 pi h^3) (-r^3 / (2 h^3) + r^2 / h^2 + h / (2 r) - 1).
    float w_viscosity(float r) const {
        if (r >= h || r <= 0.0f) return 0.0f;
        const float q = r / h;
        const float c = static_cast<float>(15.0 / (2.0 * std::numbers::pi)) / (h * h * h);
        return c * (-0.5f * q * q * q + q * q + 0.5f / q - 1.0f);
    }
    float lap_viscosity(float r) const {
        if (r >= h) return 0.0f;
        return visc_lap * (h - r);
    }
};

}  // namespace rivulet
