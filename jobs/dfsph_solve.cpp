#include "jobs/dfsph_solve.h"

namespace rivulet {

namespace {

// sum_j V grad W_ij . (v_i - v_j) over particle i's pairs, plus the walls'.
inline float rate_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                     std::span<const float> vx, std::span<const float> vy, std::span<const float> vz) {
    const float xi = c.x[i], yi = c.y[i], zi = c.z[i];
    const float vxi = vx[i], vyi = vy[i], vzi = vz[i];
    float rate = 0.0f;
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
        const DfsphPair q = l.pairs[p];
        const std::uint32_t j = q.j;
        rate += q.f * ((xi - c.x[j]) * (vxi - vx[j]) + (yi - c.y[j]) * (vyi - vy[j]) +
                       (zi - c.z[j]) * (vzi - vz[j]));
    }
    rate += c.wall_gx[i] * (vxi - c.wall_velocity[0]) + c.wall_gy[i] * (vyi - c.wall_velocity[1]) +
            c.wall_gz[i] * (vzi - c.wall_velocity[2]);
    return rate;
}

}  // namespace

double dfsph_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                      DfsphResidual kind, float dt, std::span<const float> vx, std::span<const float> vy,
                      std::span<const float> vz, std::span<const float> density_ratio,
                      std::span<const float> factor, std::span<const float> k_total, std::span<float> k,
                      float catch_up) {
    const DfsphChunkLists& l = c.lists[chunk];
    double sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) {
        const float rate = rate_of(c, l, i, vx, vy, vz);
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
        const float xi = c.x[i], yi = c.y[i], zi = c.z[i];
        const float ki = k[i];
        float dx = 0.0f, dy = 0.0f, dz = 0.0f;
        for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; ++p) {
            const DfsphPair q = l.pairs[p];
            const std::uint32_t j = q.j;
            const float s = (ki + k[j]) * q.f;
            dx += s * (xi - c.x[j]), dy += s * (yi - c.y[j]), dz += s * (zi - c.z[j]);
        }
        dx += ki * c.wall_gx[i], dy += ki * c.wall_gy[i], dz += ki * c.wall_gz[i];
        v.vx[i] -= dx, v.vy[i] -= dy, v.vz[i] -= dz;
    }
}

float dfsph_predict(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt,
                    float nu, float h, const float gravity[3], std::span<const float> vx,
                    std::span<const float> vy, std::span<const float> vz, const DfsphVelocities& out) {
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
                const float s = vr / (r2 + eps2) * q.f;
                ax += s * dx, ay += s * dy, az += s * dz;
            }
            ax *= scale, ay *= scale, az *= scale;
        }
        const float ox = vxi + dt * (ax + gravity[0]);
        const float oy = vyi + dt * (ay + gravity[1]);
        const float oz = vzi + dt * (az + gravity[2]);
        out.vx[i] = ox, out.vy[i] = oy, out.vz[i] = oz;
        const float v2 = ox * ox + oy * oy + oz * oz;
        if (v2 > max_v2) max_v2 = v2;
    }
    return max_v2;
}

}  // namespace rivulet
