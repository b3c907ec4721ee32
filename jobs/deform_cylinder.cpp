#include "jobs/deform_cylinder.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace rivulet {
namespace {

void set_position(std::span<float> v, std::uint32_t vertex, float x, float y, float z) {
    float* p = v.data() + std::size_t(vertex) * 6;
    p[0] = x, p[1] = y, p[2] = z;
}

}  // namespace

void deform_cylinder(ConstPositions p, std::span<const std::uint32_t> ring,
                     std::span<const std::uint32_t> particle, std::uint32_t vmin, std::uint32_t vmax,
                     const DeformParams& params, std::span<float> ccx, std::span<float> ccz,
                     std::span<float> crho, std::span<float> vertices) {
    const CylinderLayout& layout = params.layout;
    const std::uint32_t u = layout.u;
    const float radius = params.grid.radius;
    const float r2 = radius * radius;
    std::array<float, kMaxRingVertices> r{}, tmp{};
    const std::span<float> rs(r.data(), u), ts(tmp.data(), u);

    for (std::size_t begin = 0; begin < ring.size();) {
        const std::uint32_t v = ring[begin];
        std::size_t end = begin;
        while (end < ring.size() && ring[end] == v) ++end;
        const float plane_y = params.grid.plane_y(v);

        // Circles of this plane, then their centroid as the polar origin.
        float sum_x = 0, sum_z = 0, reach_up = 0, reach_down = 0;
        for (std::size_t e = begin; e < end; ++e) {
            const std::uint32_t i = particle[e];
            const float dy = p.y[i] - plane_y;
            ccx[e] = p.x[i], ccz[e] = p.z[i];
            crho[e] = std::sqrt(std::max(r2 - dy * dy, 0.0f));
            sum_x += p.x[i], sum_z += p.z[i];
            reach_up = std::max(reach_up, dy + radius);
            reach_down = std::max(reach_down, radius - dy);
        }
        const float inv_n = 1.0f / static_cast<float>(end - begin);
        const float ox = sum_x * inv_n, oz = sum_z * inv_n;
        for (std::size_t e = begin; e < end; ++e) ccx[e] -= ox, ccz[e] -= oz;

        const auto n = static_cast<std::ptrdiff_t>(end - begin);
        const CirclesView circles{std::span<const float>(ccx).subspan(begin, n),
                                  std::span<const float>(ccz).subspan(begin, n),
                                  std::span<const float>(crho).subspan(begin, n)};
        radial_function(params.section, circles, params.angles, rs, ts);

        for (std::uint32_t k = 0; k < u; ++k)
            set_position(vertices, layout.side_vertex(v, k), ox + r[k] * params.angles.cos_t[k], plane_y,
                         oz + r[k] * params.angles.sin_t[k]);
        // Poles: the end rings' caps reach to where the spheres end (at most one ring spacing away);
        // inner rings' poles are unused but defined so the buffer is deterministic.
        const float spacing = params.grid.spacing;
        const float up = v == vmin ? std::min(reach_up, spacing) : 0.0f;
        const float down = v == vmax ? std::min(reach_down, spacing) : 0.0f;
        set_position(vertices, layout.top_pole(v), ox, plane_y + up, oz);
        set_position(vertices, layout.bottom_pole(v), ox, plane_y - down, oz);
        begin = end;
    }
}

}  // namespace rivulet
