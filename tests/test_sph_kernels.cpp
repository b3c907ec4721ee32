// SPH kernels (jobs/sph_kernels.h, Müller et al. 2003; the cubic spline of jobs/sph_cubic_kernel.h): each
// integrates to 1 over its support, gradients
// and Laplacians match finite differences of the kernels, gradients point towards the neighbour (the
// kernels fall with distance) and are antisymmetric.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <numbers>
#include <vector>

#include "jobs/sph_cubic_kernel.h"
#include "jobs/sph_kernels.h"

namespace rivulet {
namespace {

// Integral of a radial function over the ball of radius h: int_0^h f(r) 4 pi r^2 dr, composite Simpson
// in double (the kernels are evaluated in float).
double ball_integral(const std::function<double(double)>& f, double h, int n = 20000) {
    const double step = h / n;
    double sum = 0;
    for (int i = 0; i <= n; ++i) {
        const double r = i * step;
        const double g = r > 0 ? f(r) * 4.0 * std::numbers::pi * r * r : 0.0;
        const double wgt = (i == 0 || i == n) ? 1.0 : (i % 2 ? 4.0 : 2.0);
        sum += wgt * g;
    }
    return sum * step / 3.0;
}

TEST(SphKernels, EachIntegratesToOneOverItsSupport) {
    for (float h : {0.01f, 0.04f, 1.0f}) {
        const SphKernels k(h);
        const double poly6 = ball_integral([&](double r) { return k.w_poly6(float(r * r)); }, h);
        const double spiky = ball_integral([&](double r) { return k.w_spiky(float(r)); }, h);
        const double visc = ball_integral([&](double r) { return k.w_viscosity(float(r)); }, h);
        EXPECT_NEAR(poly6, 1.0, 1e-3) << "h " << h;
        EXPECT_NEAR(spiky, 1.0, 1e-3) << "h " << h;
        EXPECT_NEAR(visc, 1.0, 1e-3) << "h " << h;
    }
}

// The cubic spline of DFSPH (jobs/sph_cubic_kernel.h): integrates to 1, its gradient is the derivative of
// W (so the density's predicted change is the change of the density), zero from r = h on.
TEST(SphKernels, CubicSplineIntegratesToOneAndItsGradientIsItsDerivative) {
    for (float h : {0.01f, 0.04f, 1.0f}) {
        const SphCubicKernel k(h);
        EXPECT_NEAR(ball_integral([&](double r) { return k.w(float(r * r)); }, h), 1.0, 1e-3) << "h " << h;
        for (double q : {0.1, 0.3, 0.5, 0.7, 0.95}) {
            const double r = q * h, e = 1e-3 * h;
            const double fd =
                (double(k.w(float((r + e) * (r + e)))) - k.w(float((r - e) * (r - e)))) / (2 * e);
            EXPECT_NEAR(double(k.grad_scale(float(r))) * r, fd, 2e-3 * std::abs(fd) + 1e-6 / (h * h * h * h))
                << "h " << h << " q " << q;
        }
        EXPECT_EQ(k.w(h * h), 0.0f);
        EXPECT_EQ(k.grad_scale(h), 0.0f);
        EXPECT_EQ(k.grad_scale(0.0f), 0.0f);
    }
}

TEST(SphKernels, ZeroOutsideSupport) {
    const SphKernels k(0.05f);
    EXPECT_EQ(k.w_poly6(0.05f * 0.05f), 0.0f);
    EXPECT_EQ(k.w_poly6(1.0f), 0.0f);
    EXPECT_EQ(k.spiky_grad_scale(0.05f), 0.0f);
    EXPECT_EQ(k.lap_viscosity(0.06f), 0.0f);
    EXPECT_EQ(k.lap_poly6(0.0026f), 0.0f);
}

TEST(SphKernels, DerivativesMatchFiniteDifferences) {
    const float h = 1.0f;
    const SphKernels k(h);
    for (double r : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const double e = 1e-3;
        const auto poly6 = [&](double s) { return double(k.w_poly6(float(s * s))); };
        const auto spiky = [&](double s) { return double(k.w_spiky(float(s))); };
        const auto visc = [&](double s) { return double(k.w_viscosity(float(s))); };
        // Radial derivative: grad W = W'(r) r_vec / r, so W'(r) = scale * r.
        const double dpoly6 = (poly6(r + e) - poly6(r - e)) / (2 * e);
        EXPECT_NEAR(double(k.poly6_grad_scale(float(r * r))) * r, dpoly6, 2e-3 * std::abs(dpoly6) + 1e-3);
        const double dspiky = (spiky(r + e) - spiky(r - e)) / (2 * e);
        EXPECT_NEAR(double(k.spiky_grad_scale(float(r))) * r, dspiky, 2e-3 * std::abs(dspiky) + 1e-3);
        // Laplacian of a radial function: W'' + 2 W' / r (a wider step: the kernels are float).
        const auto lap = [&](const std::function<double(double)>& w) {
            const double q = 1e-2;
            const double d1 = (w(r + q) - w(r - q)) / (2 * q);
            const double d2 = (w(r + q) - 2 * w(r) + w(r - q)) / (q * q);
            return d2 + 2 * d1 / r;
        };
        const double lpoly6 = lap(poly6), lvisc = lap(visc);
        EXPECT_NEAR(double(k.lap_poly6(float(r * r))), lpoly6, 1e-2 * std::abs(lpoly6) + 5e-2);
        EXPECT_NEAR(double(k.lap_viscosity(float(r))), lvisc, 1e-2 * std::abs(lvisc) + 5e-2);
    }
}

TEST(SphKernels, GradientsPointTowardsTheNeighbourAndAreAntisymmetric) {
    const SphKernels k(0.1f);
    const float pairs[][3] = {
        {0.03f, 0.01f, -0.02f}, {-0.05f, 0.02f, 0.04f}, {0.0f, 0.0f, 0.07f}, {0.001f, 0, 0}};
    for (const auto& d : pairs) {
        const float r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        const float r = std::sqrt(r2);
        // grad_i W(x_i - x_j) = scale * (x_i - x_j); grad_j W(x_j - x_i) = scale * (x_j - x_i).
        for (float scale : {k.spiky_grad_scale(r), k.poly6_grad_scale(r2)}) {
            ASSERT_LT(scale, 0.0f);  // grad . (x_i - x_j) < 0: W grows towards the neighbour
            for (int a = 0; a < 3; ++a) {
                const float gij = scale * d[a], gji = scale * -d[a];
                EXPECT_EQ(gij, -gji);
            }
        }
        EXPECT_GT(k.lap_viscosity(r), 0.0f);  // viscosity pulls velocities together
    }
    // Spiky's gradient does not vanish near the centre (Müller's reason for it): it tends to 3 * 15 / (pi
    // h^4).
    const float near = k.spiky_grad_scale(1e-4f) * 1e-4f;
    EXPECT_NEAR(near, -45.0f / (std::numbers::pi_v<float> * 1e-4f),
                0.01f * 45.0f / (std::numbers::pi_v<float> * 1e-4f));
}

}  // namespace
}  // namespace rivulet

namespace {

// Distances over the cubic spline's support, both sides of q = 1/2 among them, padded to eight lanes.
std::vector<float> cubic_spline_distances(const rivulet::SphCubicKernel& kernel) {
    std::vector<float> r;
    for (int k = 0; k <= 4000; ++k) r.push_back(kernel.h * float(k) / 4000.0f);
    const float half = 0.5f * kernel.h;
    r.insert(r.end(), {std::nextafter(half, 0.0f), half, std::nextafter(half, 1.0f), 0.0f, 1e-12f});
    while (r.size() % 8 != 0) r.push_back(0.5f * kernel.h);
    return r;
}

}  // namespace

// The cubic spline in lanes (four, or eight in the neighbour lists); each lane must give the scalar
// call's bits (the simulation's bytes do not depend on which form ran), on both sides of q = 1/2 too.
TEST(SphKernels, CubicSplineInFourLanesGivesTheScalarBits) {
    const rivulet::SphCubicKernel kernel(0.0228f);
    const std::vector<float> r = cubic_spline_distances(kernel);
    for (std::size_t i = 0; i < r.size(); i += 4) {
        rivulet::simd::F4 w4, dw4;
        kernel.at(rivulet::simd::load(&r[i]), w4, dw4);
        float w[4], dw[4];
        rivulet::simd::store(w, w4);
        rivulet::simd::store(dw, dw4);
        for (int lane = 0; lane < 4; ++lane) {
            float ws = 0.0f, dws = 0.0f;
            kernel.at(r[i + lane], ws, dws);
            EXPECT_EQ(std::bit_cast<std::uint32_t>(w[lane]), std::bit_cast<std::uint32_t>(ws)) << r[i + lane];
            EXPECT_EQ(std::bit_cast<std::uint32_t>(dw[lane]), std::bit_cast<std::uint32_t>(dws))
                << r[i + lane];
        }
    }
}

TEST(SphKernels, CubicSplineInEightLanesGivesTheScalarBits) {
    const rivulet::SphCubicKernel kernel(0.0228f);
    const std::vector<float> r = cubic_spline_distances(kernel);
    using F = rivulet::VectorLanes<8>::f;
    for (std::size_t i = 0; i < r.size(); i += 8) {
        F r8, w8, dw8;
        std::memcpy(&r8, &r[i], sizeof r8);
        kernel.at(r8, w8, dw8);
        for (int lane = 0; lane < 8; ++lane) {
            float ws = 0.0f, dws = 0.0f;
            kernel.at(r[i + lane], ws, dws);
            EXPECT_EQ(std::bit_cast<std::uint32_t>(float(w8[lane])), std::bit_cast<std::uint32_t>(ws))
                << r[i + lane];
            EXPECT_EQ(std::bit_cast<std::uint32_t>(float(dw8[lane])), std::bit_cast<std::uint32_t>(dws))
                << r[i + lane];
        }
    }
}
