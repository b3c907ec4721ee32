#include "jobs/anisotropic_kernels.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace rivulet {
namespace {

// Neighbour candidates one particle may test (a pile denser than any fluid would be quadratic).
constexpr std::uint32_t kMaxScan = 4096;

void write_sphere(KernelShapes& out, std::size_t i) {
    out.sxx[i] = out.syy[i] = out.c[i] = out.amp[i] = 1.0f;
    out.sxy[i] = out.gx[i] = out.gy[i] = 0.0f;
}

}  // namespace

void anisotropic_kernels(ConstPositions p, const CellHash& hash, std::size_t begin, std::size_t end,
                         const AnisotropyParams& params, KernelShapes out) {
    const double radius = params.radius;
    const float inv_r = 1.0f / params.radius;
    const float r2_max = params.radius * params.radius;
    for (std::size_t i = begin; i < end; ++i) {
        // Sums of w, w d and w d d^T (its six distinct entries), d the offset from particle i (so no
        // cancellation in C), in double and in visiting order.
        double wsum = 0, sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
        std::uint32_t count = 0;
        for_each_within(hash, p.x[i], p.y[i], p.z[i], r2_max, kMaxScan,
                        [&](std::uint32_t, float dx, float dy, float dz, float r2) {
                            const float q = std::sqrt(r2) * inv_r;
                            const double w = double(1.0f - q * q * q), wx = w * dx, wy = w * dy, wz = w * dz;
                            wsum += w, sx += wx, sy += wy, sz += wz;
                            sxx += wx * dx, sxy += wx * dy, sxz += wx * dz, syy += wy * dy, syz += wy * dz,
                                szz += wz * dz;
                            ++count;
                        });
        const Eigen::Vector3d first(sx, sy, sz);
        Eigen::Matrix3d second;
        second << sxx, sxy, sxz, sxy, syy, syz, sxz, syz, szz;
        const Eigen::Vector3d mean = first / wsum;  // i itself has weight 1: wsum >= 1
        const double lambda = params.smoothing;
        out.x[i] = static_cast<float>(double(p.x[i]) + lambda * mean.x());
        out.y[i] = static_cast<float>(double(p.y[i]) + lambda * mean.y());
        out.z[i] = static_cast<float>(double(p.z[i]) + lambda * mean.z());
        if (count < params.min_neighbours) {
            write_sphere(out, i);
            continue;
        }
        const Eigen::Matrix3d cov = second / wsum - mean * mean.transpose();
        // The closed form for 3 x 3 (the iterative solver took two thirds of the job); where it is less
        // accurate, nearly equal eigenvalues, their axes come out nearly equal too and their directions
        // hardly matter.
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
        eig.computeDirect(cov);
        const Eigen::Vector3d var = eig.eigenvalues();  // ascending
        const double var_max = std::max(var(2), 0.0);
        // Neighbours all (nearly) on one point: no shape to follow.
        if (eig.info() != Eigen::Success || !(var_max > 1e-6 * radius * radius)) {
            write_sphere(out, i);
            continue;
        }
        const double least = var_max / params.max_stretch;
        Eigen::Vector3d axes;
        for (int k = 0; k < 3; ++k) axes(k) = std::max(std::max(var(k), 0.0), least);
        axes /= axes.minCoeff();
        const Eigen::Matrix3d& rot = eig.eigenvectors();
        const Eigen::Matrix3d m = rot * axes.cwiseInverse().cwiseAbs2().asDiagonal() * rot.transpose();
        const double czz = m(2, 2), gx = -m(0, 2) / czz, gy = -m(1, 2) / czz;
        out.sxx[i] = static_cast<float>(m(0, 0) - m(0, 2) * m(0, 2) / czz);
        out.sxy[i] = static_cast<float>(m(0, 1) - m(0, 2) * m(1, 2) / czz);
        out.syy[i] = static_cast<float>(m(1, 1) - m(1, 2) * m(1, 2) / czz);
        out.gx[i] = static_cast<float>(gx), out.gy[i] = static_cast<float>(gy);
        out.c[i] = static_cast<float>(czz);
        out.amp[i] = static_cast<float>(1.0 / axes.prod());
    }
}

}  // namespace rivulet
