#include "jobs/anisotropic_kernels.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>

#include "jobs/vector_lanes.h"

namespace rivulet {
namespace {

// Neighbour candidates one particle may test (a pile denser than any fluid would be quadratic).
constexpr std::uint32_t kMaxScan = 4096;

void write_sphere(KernelShapes& out, std::size_t i) {
    out.sxx[i] = out.syy[i] = out.c[i] = out.amp[i] = 1.0f;
    out.sxy[i] = out.gx[i] = out.gy[i] = 0.0f;
}

// The weighted sums of a particle's neighbours within the radius: w, w d and w d d^T (its six distinct
// entries), d the offset from the particle (so no cancellation in C), w = 1 - (|d| / radius)^3. Four
// candidates a vector in bucket order (the cells wholly beyond the radius skipped), those outside the
// radius weighted 0 (no branch: about one in five candidates is a neighbour, at random), each lane's sums
// in float, the lanes added in double in a fixed order: the same bits whoever runs it.
struct NeighbourSums {
    double w = 0, x = 0, y = 0, z = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
    std::uint32_t count = 0;
};

NeighbourSums neighbour_sums(const CellHash& hash, float x, float y, float z, float radius) {
    using fv = VectorLanes<4>::f;
    using iv = VectorLanes<4>::i;
    const fv vx = fv{} + x, vy = fv{} + y, vz = fv{} + z, vr2 = fv{} + radius * radius;
    const fv inv_r = fv{} + 1.0f / radius, one = fv{} + 1.0f, zero = fv{};
    fv w{}, sx{}, sy{}, sz{}, sxx{}, sxy{}, sxz{}, syy{}, syz{}, szz{};
    iv count{};
    const auto add = [&](const fv& px, const fv& py, const fv& pz, const iv& valid) {
        const fv dx = px - vx, dy = py - vy, dz = pz - vz;
        const fv r2 = dx * dx + dy * dy + dz * dz;
        const iv hit = valid & (r2 < vr2);
        fv q;
        lane_sqrt(r2, q);
        q = q * inv_r;
        const fv wl = hit ? one - q * q * q : zero;
        const fv wx = wl * dx, wy = wl * dy, wz = wl * dz;
        w += wl, sx += wx, sy += wy, sz += wz;
        sxx += wx * dx, sxy += wx * dy, sxz += wx * dz, syy += wy * dy, syz += wy * dz, szz += wz * dz;
        count -= hit;
    };
    for_each_bucket_within(hash, x, y, z, radius, kMaxScan, [&](std::uint32_t begin, std::uint32_t end) {
        std::uint32_t e = begin;
        const iv all = iv{} - 1;
        for (; e + 4 <= end; e += 4) {
            fv px, py, pz;
            std::memcpy(&px, hash.sx.data() + e, sizeof px);
            std::memcpy(&py, hash.sy.data() + e, sizeof py);
            std::memcpy(&pz, hash.sz.data() + e, sizeof pz);
            add(px, py, pz, all);
        }
        if (e < end) {
            fv px = vx, py = vy, pz = vz;
            iv valid{};
            for (std::uint32_t l = 0; e + l < end; ++l)
                px[l] = hash.sx[e + l], py[l] = hash.sy[e + l], pz[l] = hash.sz[e + l], valid[l] = -1;
            add(px, py, pz, valid);
        }
    });
    const auto total = [](const fv& v) {
        return (double(v[0]) + double(v[1])) + (double(v[2]) + double(v[3]));
    };
    return {total(w),
            total(sx),
            total(sy),
            total(sz),
            total(sxx),
            total(sxy),
            total(sxz),
            total(syy),
            total(syz),
            total(szz),
            std::uint32_t(count[0] + count[1] + count[2] + count[3])};
}

}  // namespace

void anisotropic_kernels(ConstPositions p, const CellHash& hash, std::size_t begin, std::size_t end,
                         const AnisotropyParams& params, KernelShapes out) {
    const double radius = params.radius;
    for (std::size_t i = begin; i < end; ++i) {
        const NeighbourSums n = neighbour_sums(hash, p.x[i], p.y[i], p.z[i], params.radius);
        const Eigen::Vector3d first(n.x, n.y, n.z);
        Eigen::Matrix3d second;
        second << n.xx, n.xy, n.xz, n.xy, n.yy, n.yz, n.xz, n.yz, n.zz;
        const Eigen::Vector3d mean = first / n.w;  // i itself has weight 1: n.w >= 1
        const double lambda = params.smoothing;
        out.x[i] = static_cast<float>(double(p.x[i]) + lambda * mean.x());
        out.y[i] = static_cast<float>(double(p.y[i]) + lambda * mean.y());
        out.z[i] = static_cast<float>(double(p.z[i]) + lambda * mean.z());
        if (n.count < params.min_neighbours) {
            write_sphere(out, i);
            continue;
        }
        const Eigen::Matrix3d cov = second / n.w - mean * mean.transpose();
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
