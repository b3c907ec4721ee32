#include "jobs/deform_cylinder.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rivulet {
namespace {

// Where one ring's polar origin lies and how far its spheres reach above and below its plane.
struct RingFrame {
    std::uint32_t v;
    float ox, oz, y, reach_up, reach_down;
};

// The circles of one ring's entries [begin, end) into the scratch, relative to their centroid.
RingFrame ring_circles(ConstPositions p, std::span<const std::uint32_t> particle, std::size_t begin,
                       std::size_t end, std::uint32_t v, const DeformParams& params, float* ccx, float* ccz,
                       float* crho) {
    const float plane_y = params.grid.plane_y(v);
    const float radius = params.grid.radius;
    const float r2 = radius * radius;
    float sum_x = 0, sum_z = 0, reach_up = 0, reach_down = 0;
    for (std::size_t e = begin; e < end; ++e) {
        const std::uint32_t i = particle[e];
        const float dy = p.y[i] - plane_y;
        ccx[e] = p.x[i], ccz[e] = p.z[i], crho[e] = dy;
        sum_x += p.x[i], sum_z += p.z[i];
        reach_up = std::max(reach_up, dy + radius);
        reach_down = std::max(reach_down, radius - dy);
    }
    const float inv_n = 1.0f / static_cast<float>(end - begin);
    const float ox = sum_x * inv_n, oz = sum_z * inv_n;
    // Apart from the gathers above, so that the square roots run in vector lanes.
    for (std::size_t e = begin; e < end; ++e) {
        ccx[e] -= ox, ccz[e] -= oz;
        crho[e] = std::sqrt(std::max(r2 - crho[e] * crho[e], 0.0f));
    }
    return {v, ox, oz, plane_y, reach_up, reach_down};
}

void set_position(std::span<float> v, std::uint32_t vertex, float x, float y, float z) {
    float* p = v.data() + std::size_t(vertex) * 6;
    p[0] = x, p[1] = y, p[2] = z;
}

// Lane `lane` of the interleaved radii (r[k * kSmoothLanes + lane]) as the ring's vertices. The end
// rings' poles close the tube where the spheres end (at most one ring spacing away); inner rings' poles
// are unused but defined so the buffer is deterministic.
void write_ring(const RingFrame& f, const float* r, std::size_t lane, std::uint32_t vmin, std::uint32_t vmax,
                const DeformParams& params, std::span<float> vertices) {
    const CylinderLayout& layout = params.layout;
    for (std::uint32_t k = 0; k < layout.u; ++k) {
        const float rk = r[k * kSmoothLanes + lane];
        set_position(vertices, layout.side_vertex(f.v, k), f.ox + rk * params.angles.cos_t[k], f.y,
                     f.oz + rk * params.angles.sin_t[k]);
    }
    const float spacing = params.grid.spacing;
    const float up = f.v == vmin ? std::min(f.reach_up, spacing) : 0.0f;
    const float down = f.v == vmax ? std::min(f.reach_down, spacing) : 0.0f;
    set_position(vertices, layout.top_pole(f.v), f.ox, f.y + up, f.oz);
    set_position(vertices, layout.bottom_pole(f.v), f.ox, f.y - down, f.oz);
}

}  // namespace

void deform_cylinder(ConstPositions p, std::span<const std::uint32_t> ring,
                     std::span<const std::uint32_t> particle, std::uint32_t vmin, std::uint32_t vmax,
                     const DeformParams& params, std::span<float> ccx, std::span<float> ccz,
                     std::span<float> crho, std::span<float> vertices) {
    const std::uint32_t u = params.layout.u;
    const bool maxima = params.section.function == RadialFunction::kCircleMaxima;
    std::array<float, kMaxRingVertices> r, tmp;
    const std::span<float> rs(r.data(), u), ts(tmp.data(), u);
    // Rings are smoothed kSmoothLanes at a time, interleaved (cross_section.h).
    std::array<float, kMaxRingVertices * kSmoothLanes> batch, batch_tmp;
    std::array<RingFrame, kSmoothLanes> frames;

    for (std::size_t begin = 0; begin < ring.size();) {
        std::size_t lanes = 0;
        for (; lanes < kSmoothLanes && begin < ring.size(); ++lanes) {
            const std::uint32_t v = ring[begin];
            std::size_t end = begin;
            while (end < ring.size() && ring[end] == v) ++end;
            frames[lanes] =
                ring_circles(p, particle, begin, end, v, params, ccx.data(), ccz.data(), crho.data());
            const auto n = static_cast<std::ptrdiff_t>(end - begin);
            const CirclesView circles{std::span<const float>(ccx).subspan(begin, n),
                                      std::span<const float>(ccz).subspan(begin, n),
                                      std::span<const float>(crho).subspan(begin, n)};
            if (maxima)
                circle_maxima(circles, params.angles, rs);
            else
                gaussian_blend(circles, params.angles, params.section.tension, rs, ts);
            for (std::uint32_t k = 0; k < u; ++k) batch[k * kSmoothLanes + lanes] = r[k];
            begin = end;
        }
        if (maxima) {
            for (std::size_t j = lanes; j < kSmoothLanes; ++j)  // idle lanes: any finite value will do
                for (std::uint32_t k = 0; k < u; ++k) batch[k * kSmoothLanes + j] = 0.0f;
            smooth_cyclic_rings(std::span<float>(batch.data(), u * kSmoothLanes), u,
                                params.section.smoothing_iterations, batch_tmp);
        }
        for (std::size_t j = 0; j < lanes; ++j)
            write_ring(frames[j], batch.data(), j, vmin, vmax, params, vertices);
    }
}

}  // namespace rivulet
