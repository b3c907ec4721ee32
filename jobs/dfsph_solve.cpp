#include "jobs/dfsph_solve.h"

#include "jobs/simd4.h"

namespace rivulet {

namespace {

// V grad W_ij of pair q of particle i (at xi): the pair's radial factor times x_i - x_j, the build's
// own product from the same floats.
inline simd::F4 pair_gradient(const DfsphContext& c, simd::F4 xi, const DfsphPair& q) {
    return simd::splat(q.f) * (xi - simd::load(&c.x4[4 * std::size_t(q.j)]));
}

// sum_j V grad W_ij . (v_i - v_j) over particle i's pairs, plus the walls': the three products summed
// per axis in lanes, the axes added at the end.
inline float rate_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                     std::span<const float> v4) {
    const simd::F4 vi = simd::load(&v4[4 * i]);
    const simd::F4 xi = simd::load(&c.x4[4 * i]);
    simd::F4 sum = simd::splat(0.0f);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
        const DfsphPair& q = l.pairs[p];
        sum = sum + pair_gradient(c, xi, q) * (vi - simd::load(&v4[4 * std::size_t(q.j)]));
    }
    alignas(16) float s[4];
    simd::store(s, sum);
    float rate = (s[0] + s[1]) + s[2];
    const float* v = &v4[4 * i];
    rate += c.wall_gx[i] * (v[0] - c.wall_velocity[0]) + c.wall_gy[i] * (v[1] - c.wall_velocity[1]) +
            c.wall_gz[i] * (v[2] - c.wall_velocity[2]);
    return rate;
}

// sum_j (k_i + k_j) V grad W_ij + k_i grad B_i, the velocity change of particle i: the three sums in lanes
// 0-2, each the scalar sum's operations in the same order.
inline void correction_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                          std::span<const float> k, float d[3]) {
    const float ki = k[i];
    const simd::F4 xi = simd::load(&c.x4[4 * i]);
    simd::F4 sum = simd::splat(0.0f);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
        const DfsphPair& q = l.pairs[p];
        sum = sum + simd::splat(ki + k[q.j]) * pair_gradient(c, xi, q);
    }
    alignas(16) float lanes[4];
    simd::store(lanes, sum);
    d[0] = lanes[0] + ki * c.wall_gx[i], d[1] = lanes[1] + ki * c.wall_gy[i],
    d[2] = lanes[2] + ki * c.wall_gz[i];
}

// sum_j (v_ij . x_ij) / (r_ij^2 + eps2) V grad W_ij over particle i's pairs (the viscosity's sum, Monaghan's
// form): four pairs to a vector, a pair a lane, their neighbours' columns gathered; a missing pair is i
// itself, which adds +0. Each lane's sums are added in a fixed order at the end.
inline void viscosity_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                         std::span<const float> vx, std::span<const float> vy, std::span<const float> vz,
                         float eps2, float a[3]) {
    using simd::F4;
    const F4 xi = simd::splat(c.x[i]), yi = simd::splat(c.y[i]), zi = simd::splat(c.z[i]);
    const F4 vxi = simd::splat(vx[i]), vyi = simd::splat(vy[i]), vzi = simd::splat(vz[i]);
    const F4 e2 = simd::splat(eps2);
    F4 ax = simd::splat(0.0f), ay = ax, az = ax;
    const auto self = static_cast<std::uint32_t>(i);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; p += 4) {
        const std::uint32_t n = c.pair_end[i] - p;
        const DfsphPair none{0.0f, self};
        const DfsphPair& q0 = l.pairs[p];
        const DfsphPair& q1 = n > 1 ? l.pairs[p + 1] : none;
        const DfsphPair& q2 = n > 2 ? l.pairs[p + 2] : none;
        const DfsphPair& q3 = n > 3 ? l.pairs[p + 3] : none;
        const std::uint32_t j0 = q0.j, j1 = q1.j, j2 = q2.j, j3 = q3.j;
        const F4 dx = xi - simd::make(c.x[j0], c.x[j1], c.x[j2], c.x[j3]);
        const F4 dy = yi - simd::make(c.y[j0], c.y[j1], c.y[j2], c.y[j3]);
        const F4 dz = zi - simd::make(c.z[j0], c.z[j1], c.z[j2], c.z[j3]);
        const F4 r2 = dx * dx + dy * dy + dz * dz;
        const F4 vr = (vxi - simd::make(vx[j0], vx[j1], vx[j2], vx[j3])) * dx +
                      (vyi - simd::make(vy[j0], vy[j1], vy[j2], vy[j3])) * dy +
                      (vzi - simd::make(vz[j0], vz[j1], vz[j2], vz[j3])) * dz;
        const F4 s = vr / (r2 + e2);
        const F4 f = simd::make(q0.f, q1.f, q2.f, q3.f);
        ax = ax + s * (f * dx);
        ay = ay + s * (f * dy);
        az = az + s * (f * dz);
    }
    a[0] = simd::sum(ax), a[1] = simd::sum(ay), a[2] = simd::sum(az);
}

}  // namespace

double dfsph_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                      DfsphResidual kind, float dt, std::span<const float> v4,
                      std::span<const float> density_ratio, std::span<const float> factor,
                      std::span<const float> k_total, std::span<float> k, float catch_up) {
    const DfsphChunkLists& l = c.lists[chunk];
    double sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) {
        const float rate = rate_of(c, l, i, v4);
        float r = 0.0f;  // signed residual, per second
        if (kind == DfsphResidual::kDivergence) {
            r = c.support[i] >= c.min_support ? rate : 0.0f;
        } else {
            r = ((density_ratio[i] - 1.0f) * catch_up + dt * rate) / dt;
        }
        const float total = k_total[i] + kDfsphRelaxation * r * factor[i];
        k[i] = (total > 0.0f ? total : 0.0f) - k_total[i];
        sum += r > 0.0f ? double(r) * dt : 0.0;
    }
    return sum;
}

void dfsph_correct(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                   std::span<const float> k, const DfsphVelocities& v) {
    const DfsphChunkLists& l = c.lists[chunk];
    for (std::size_t i = begin; i < end; ++i) {
        float d[3];
        correction_of(c, l, i, k, d);
        const float vx = v.vx[i] - d[0], vy = v.vy[i] - d[1], vz = v.vz[i] - d[2];
        v.vx[i] = vx, v.vy[i] = vy, v.vz[i] = vz;
        v.v4[4 * i] = vx, v.v4[4 * i + 1] = vy, v.v4[4 * i + 2] = vz;
    }
}

float dfsph_predict(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt,
                    float nu, float h, const float gravity[3], std::span<const float> vx,
                    std::span<const float> vy, std::span<const float> vz, std::span<const float> k_warm,
                    const DfsphVelocities& out) {
    const DfsphChunkLists& l = c.lists[chunk];
    const float eps2 = 0.01f * h * h;
    const float scale = 10.0f * nu;
    float max_v2 = 0.0f;
    for (std::size_t i = begin; i < end; ++i) {
        const float vxi = vx[i], vyi = vy[i], vzi = vz[i];
        float ax = 0.0f, ay = 0.0f, az = 0.0f;
        if (scale > 0.0f) {
            float a[3];
            viscosity_of(c, l, i, vx, vy, vz, eps2, a);
            ax = a[0] * scale, ay = a[1] * scale, az = a[2] * scale;
        }
        const float px = vxi + dt * (ax + gravity[0]);
        const float py = vyi + dt * (ay + gravity[1]);
        const float pz = vzi + dt * (az + gravity[2]);
        const float v2 = px * px + py * py + pz * pz;
        if (v2 > max_v2) max_v2 = v2;
        float d[3];
        correction_of(c, l, i, k_warm, d);  // the pairs again, while they are in cache
        const float ox = px - d[0], oy = py - d[1], oz = pz - d[2];
        out.vx[i] = ox, out.vy[i] = oy, out.vz[i] = oz;
        out.v4[4 * i] = ox, out.v4[4 * i + 1] = oy, out.v4[4 * i + 2] = oz, out.v4[4 * i + 3] = 0.0f;
    }
    return max_v2;
}

}  // namespace rivulet
