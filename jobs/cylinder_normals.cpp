#include "jobs/cylinder_normals.h"

#include <cmath>

namespace rivulet {
namespace {

void accumulate_face(float* v, std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    float* pa = v + std::size_t(a) * 6;
    float* pb = v + std::size_t(b) * 6;
    float* pc = v + std::size_t(c) * 6;
    const float e1x = pb[0] - pa[0], e1y = pb[1] - pa[1], e1z = pb[2] - pa[2];
    const float e2x = pc[0] - pa[0], e2y = pc[1] - pa[1], e2z = pc[2] - pa[2];
    const float nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
    for (float* q : {pa, pb, pc}) q[3] += nx, q[4] += ny, q[5] += nz;
}

}  // namespace

void cylinder_normals(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                      std::span<float> vertices) {
    float* v = vertices.data();
    const std::uint32_t u = layout.u;
    const std::uint32_t first = layout.ring_first_vertex(vmin), last = layout.ring_first_vertex(vmax + 1);
    for (std::uint32_t i = first; i < last; ++i) v[6 * i + 3] = v[6 * i + 4] = v[6 * i + 5] = 0.0f;

    // Same triangles, same winding as write_cylinder_indices, walked ring by ring.
    for (std::uint32_t b = vmin; b < vmax; ++b) {
        const std::uint32_t ring = layout.ring_first_vertex(b), below = layout.ring_first_vertex(b + 1);
        for (std::uint32_t k = 0; k < u; ++k) {
            const std::uint32_t k1 = k + 1 == u ? 0 : k + 1;
            accumulate_face(v, ring + k, below + k1, below + k);
            accumulate_face(v, ring + k, ring + k1, below + k1);
        }
    }
    const std::uint32_t top = layout.ring_first_vertex(vmin), bottom = layout.ring_first_vertex(vmax);
    for (std::uint32_t k = 0; k < u; ++k) {
        const std::uint32_t k1 = k + 1 == u ? 0 : k + 1;
        accumulate_face(v, layout.top_pole(vmin), top + k1, top + k);
        accumulate_face(v, layout.bottom_pole(vmax), bottom + k, bottom + k1);
    }

    for (std::uint32_t i = first; i < last; ++i) {
        float* n = v + std::size_t(i) * 6 + 3;
        const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len > 1e-20f) {
            const float inv = 1.0f / len;
            n[0] *= inv, n[1] *= inv, n[2] *= inv;
        } else {
            // Collapsed neighbourhood (zero-area faces, or an inner ring's unused pole): point up so the
            // normal stays unit length; such a vertex covers no visible area.
            n[0] = 0.0f, n[1] = 1.0f, n[2] = 0.0f;
        }
    }
}

}  // namespace rivulet
