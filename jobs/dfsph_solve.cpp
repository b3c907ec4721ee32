#include "jobs/dfsph_solve.h"

#include "jobs/simd4.h"

namespace rivulet {

namespace {

// sum_j V grad W_ij . (v_i - v_j) over particle i's pairs, plus the walls': the three products summed
// per axis in lanes, the axes added at the end.
inline float rate_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                     std::span<const float> v4) {
    const simd::F4 vi = simd::load(&v4[4 * i]);
    simd::F4 sum = simd::splat(0.0f);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
        const DfsphPair& q = l.pairs[p];
        sum = sum + simd::load3(&q) * (vi - simd::load(&v4[4 * std::size_t(q.j)]));
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
    simd::F4 sum = simd::splat(0.0f);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
        const DfsphPair& q = l.pairs[p];
        sum = sum + simd::splat(ki + k[q.j]) * simd::load3(&q);
    }
    alignas(16) float lanes[4];
    simd::store(lanes, sum);
    d[0] = lanes[0] + ki * c.wall_gx[i], d[1] = lanes[1] + ki * c.wall_gy[i],
    d[2] = lanes[2] + ki * c.wall_gz[i];
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
        const float xi = c.x[i], yi = c.y[i], zi = c.z[i];
        const float vxi = vx[i], vyi = vy[i], vzi = vz[i];
        float ax = 0.0f, ay = 0.0f, az = 0.0f;
        if (scale > 0.0f) {
            for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
                const DfsphPair q = l.pairs[p];
                const std::uint32_t j = q.j;
                const float dx = xi - c.x[j], dy = yi - c.y[j], dz = zi - c.z[j];
                const float r2 = dx * dx + dy * dy + dz * dz;
                const float vr = (vxi - vx[j]) * dx + (vyi - vy[j]) * dy + (vzi - vz[j]) * dz;
                const float s = vr / (r2 + eps2);
                ax += s * q.gx, ay += s * q.gy, az += s * q.gz;
            }
            ax *= scale, ay *= scale, az *= scale;
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
