#pragma once
// Radial cross-section functions of sphere scan conversion (Hoetzlein & Höllerer 2009 §2.3, Appendix A). The
// spheres of a group cut a cross-section plane in circles; with the circles' centroid as origin, r(theta) at
// the U angles of the cylinder gives the ring of vertices.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rivulet {

enum class RadialFunction : std::uint8_t { kCircleMaxima, kGaussianBlend };

struct CrossSectionParams {
    RadialFunction function = RadialFunction::kCircleMaxima;
    int smoothing_iterations = 10;  // I, circle maxima
    float tension = 1.0f;           // k, gaussian blend
};

// Circles relative to the origin: centre (cx, cz) and radius rho, in the plane's (x, z) coordinates.
struct CirclesView {
    std::span<const float> cx, cz, rho;
    std::size_t size() const { return cx.size(); }
};

// Angles: cos_t[k], sin_t[k] of theta_k = 2 pi k / U.
struct AngleTable {
    std::span<const float> cos_t, sin_t;
};

// Fills cos_t[k], sin_t[k] for k < U = cos_t.size() (sin_t as long), computed in double.
void fill_angle_table(std::span<float> cos_t, std::span<float> sin_t);

// Equation (1): the farthest intersection of the ray at theta with any circle. Where a ray misses a
// circle the circle contributes its closest approach to the ray instead, which keeps r(theta) continuous
// (the paper leaves misses unspecified).
void circle_maxima(CirclesView circles, AngleTable angles, std::span<float> r);

// The paper's 3-point iterative smoothing, weights (1/4, 1/2, 1/4), cyclic in theta; `tmp` as large as r.
void smooth_cyclic(std::span<float> r, int iterations, std::span<float> tmp);

// The same smoothing for kSmoothLanes rings at once, interleaved: r[k * kSmoothLanes + j] is ring j's
// value at angle k (u angles). Each ring gets the same bytes as smooth_cyclic on its own; `tmp` as
// large as r.
inline constexpr std::size_t kSmoothLanes = 8;
void smooth_cyclic_rings(std::span<float> r, std::size_t u, int iterations, std::span<float> tmp);

// Equations (2)-(3) with the blend of Appendix A: gauss_i = exp(-w_i (1 - U.Cdir)), peak 1 towards the
// circle, h_i = Cdist + Cradius, w_i = k Cdist^2 / Cradius; alpha saturates at 1. Every r(theta) is a
// convex combination of the gaussians' extents, so it never exceeds max_i h_i gauss_i(theta).
// `alpha` is scratch as large as r.
void gaussian_blend(CirclesView circles, AngleTable angles, float tension, std::span<float> r,
                    std::span<float> alpha);

}  // namespace rivulet
