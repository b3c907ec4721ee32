#include "jobs/cylinder_normals.h"

#include <array>
#include <cmath>
#include <utility>

#include "jobs/cpu_dispatch.h"
#include "jobs/deform_cylinder.h"

namespace rivulet {
namespace {

// One ring's side vertices in SoA, with slot u repeating slot 0 so "k + 1" needs no wrap in the loops.
struct Ring {
    std::array<float, kMaxRingVertices + 1> x, y, z;
};

struct Normals {
    std::array<float, kMaxRingVertices + 1> x, y, z;
};

RIVULET_INLINE void load_ring(const float* v, std::uint32_t first, std::uint32_t u, Ring& r) {
    for (std::uint32_t k = 0; k < u; ++k) {
        const float* p = v + std::size_t(first + k) * 6;
        r.x[k] = p[0], r.y[k] = p[1], r.z[k] = p[2];
    }
    r.x[u] = r.x[0], r.y[u] = r.y[0], r.z[u] = r.z[0];
}

RIVULET_INLINE void cross_into(float ax, float ay, float az, float bx, float by, float bz, float& nx,
                               float& ny, float& nz) {
    nx = ay * bz - az * by, ny = az * bx - ax * bz, nz = ax * by - ay * bx;
}

// Band between rings a (above) and b (below), quad k = (a_k, a_k1, b_k1, b_k), split as the index buffer
// does (write_cylinder_indices): t1 = (a_k, b_k1, b_k), t2 = (a_k, a_k1, b_k1). Adds each face normal
// (edge cross product, so area-weighted) to its three corners' sums.
// Always inlined: each call site then knows its four arrays are distinct, and the loops vectorize.
RIVULET_INLINE void add_band(std::uint32_t u, const Ring& a, const Ring& b, Normals& na, Normals& nb) {
    std::array<float, kMaxRingVertices + 1> sx, sy, sz, tx, ty, tz;  // t1 and t1 + t2 per quad
    for (std::uint32_t k = 0; k < u; ++k) {
        const float d1x = b.x[k + 1] - a.x[k], d1y = b.y[k + 1] - a.y[k], d1z = b.z[k + 1] - a.z[k];
        const float d2x = b.x[k] - a.x[k], d2y = b.y[k] - a.y[k], d2z = b.z[k] - a.z[k];
        const float d3x = a.x[k + 1] - a.x[k], d3y = a.y[k + 1] - a.y[k], d3z = a.z[k + 1] - a.z[k];
        float n1x, n1y, n1z, n2x, n2y, n2z;
        cross_into(d1x, d1y, d1z, d2x, d2y, d2z, n1x, n1y, n1z);  // t1: (b_k1 - a_k) x (b_k - a_k)
        cross_into(d3x, d3y, d3z, d1x, d1y, d1z, n2x, n2y, n2z);  // t2: (a_k1 - a_k) x (b_k1 - a_k)
        tx[k + 1] = n1x, ty[k + 1] = n1y, tz[k + 1] = n1z;
        sx[k + 1] = n1x + n2x, sy[k + 1] = n1y + n2y, sz[k + 1] = n1z + n2z;
        // a_k and b_k1 touch both triangles of quad k; a_k1 only t2; b_k only t1.
        na.x[k] += sx[k + 1], na.y[k] += sy[k + 1], na.z[k] += sz[k + 1];
        nb.x[k] += n1x, nb.y[k] += n1y, nb.z[k] += n1z;
    }
    // Quad k - 1 reaches a_k through t2 and b_k through both triangles (cyclic: quad -1 is quad u - 1).
    sx[0] = sx[u], sy[0] = sy[u], sz[0] = sz[u];
    tx[0] = tx[u], ty[0] = ty[u], tz[0] = tz[u];
    for (std::uint32_t k = 0; k < u; ++k) {
        na.x[k] += sx[k] - tx[k], na.y[k] += sy[k] - ty[k], na.z[k] += sz[k] - tz[k];
        nb.x[k] += sx[k], nb.y[k] += sy[k], nb.z[k] += sz[k];
    }
}

// Cap fan from `pole` over ring r: triangles (pole, r_k1, r_k) on top, (pole, r_k, r_k1) at the bottom.
// Adds to the ring's sums and returns the pole's sum in (px, py, pz).
RIVULET_INLINE void add_cap(std::uint32_t u, const float* pole, const Ring& r, bool top, Normals& nr,
                            float& px, float& py, float& pz) {
    px = py = pz = 0.0f;
    for (std::uint32_t k = 0; k < u; ++k) {
        const float ax = r.x[k] - pole[0], ay = r.y[k] - pole[1], az = r.z[k] - pole[2];
        const float bx = r.x[k + 1] - pole[0], by = r.y[k + 1] - pole[1], bz = r.z[k + 1] - pole[2];
        float nx, ny, nz;
        if (top)
            cross_into(bx, by, bz, ax, ay, az, nx, ny, nz);
        else
            cross_into(ax, ay, az, bx, by, bz, nx, ny, nz);
        px += nx, py += ny, pz += nz;
        nr.x[k] += nx, nr.y[k] += ny, nr.z[k] += nz;
        const std::uint32_t k1 = k + 1 == u ? 0 : k + 1;
        nr.x[k1] += nx, nr.y[k1] += ny, nr.z[k1] += nz;
    }
}

// Unit normal of a summed face normal; a collapsed neighbourhood (zero-area faces, or an inner ring's
// unused pole) points up so the normal stays unit length: such a vertex covers no visible area.
RIVULET_INLINE void unit_normal(float& nx, float& ny, float& nz) {
    const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
    const bool defined = len > 1e-20f;
    const float inv = 1.0f / (defined ? len : 1.0f);  // no division by zero in the lanes not taken
    nx = defined ? nx * inv : 0.0f;
    ny = defined ? ny * inv : 1.0f;
    nz = defined ? nz * inv : 0.0f;
}

RIVULET_INLINE void store_normal(float* vertex, float nx, float ny, float nz) {
    unit_normal(nx, ny, nz);
    vertex[3] = nx, vertex[4] = ny, vertex[5] = nz;
}

// Normalised in SoA first (vector lanes), then written into the interleaved vertices.
RIVULET_INLINE void store_ring(float* v, const CylinderLayout& layout, std::uint32_t ring, Normals& n) {
    for (std::uint32_t k = 0; k < layout.u; ++k) unit_normal(n.x[k], n.y[k], n.z[k]);
    float* out = v + std::size_t(layout.side_vertex(ring, 0)) * 6;
    for (std::uint32_t k = 0; k < layout.u; ++k)
        out[k * 6 + 3] = n.x[k], out[k * 6 + 4] = n.y[k], out[k * 6 + 5] = n.z[k];
}

RIVULET_INLINE void clear(Normals& n, std::uint32_t u) {
    for (std::uint32_t k = 0; k < u; ++k) n.x[k] = n.y[k] = n.z[k] = 0.0f;
}

RIVULET_INLINE void cylinder_normals_body(const CylinderLayout& layout, std::uint32_t vmin,
                                          std::uint32_t vmax, std::uint32_t first, std::uint32_t last,
                                          std::span<float> vertices) {
    float* v = vertices.data();
    const std::uint32_t u = layout.u;
    // Rolling window of two rings: ring b's sums start with band b-1 (or the top cap) and are complete
    // once band b (or the bottom cap) is added, in that order for every range.
    Ring rings[2];
    Normals sums[2], unused;
    Ring* above = &rings[0];
    Ring* below = &rings[1];
    Normals* n_above = &sums[0];
    Normals* n_below = &sums[1];
    float px, py, pz;
    if (first == vmin) {
        load_ring(v, layout.ring_first_vertex(first), u, *above);
        clear(*n_above, u);
        add_cap(u, v + std::size_t(layout.top_pole(vmin)) * 6, *above, true, *n_above, px, py, pz);
        store_normal(v + std::size_t(layout.top_pole(vmin)) * 6, px, py, pz);
    } else {
        // Band first-1 as seen from ring `first`; the ring above belongs to another range.
        load_ring(v, layout.ring_first_vertex(first - 1), u, *below);
        load_ring(v, layout.ring_first_vertex(first), u, *above);
        clear(*n_above, u);
        clear(unused, u);
        add_band(u, *below, *above, unused, *n_above);
    }
    for (std::uint32_t b = first; b < last; ++b) {
        load_ring(v, layout.ring_first_vertex(b + 1), u, *below);
        clear(*n_below, u);
        add_band(u, *above, *below, *n_above, *n_below);
        store_ring(v, layout, b, *n_above);
        std::swap(above, below);
        std::swap(n_above, n_below);
    }
    if (last == vmax) {
        add_cap(u, v + std::size_t(layout.bottom_pole(vmax)) * 6, *above, false, *n_above, px, py, pz);
        store_normal(v + std::size_t(layout.bottom_pole(vmax)) * 6, px, py, pz);
    } else {
        load_ring(v, layout.ring_first_vertex(last + 1), u, *below);
        clear(unused, u);
        add_band(u, *above, *below, *n_above, unused);
    }
    store_ring(v, layout, last, *n_above);
    // Poles of inner rings are not drawn; give them a defined unit normal so the buffer is deterministic.
    for (std::uint32_t b = first; b <= last; ++b) {
        if (b != vmin) store_normal(v + std::size_t(layout.top_pole(b)) * 6, 0.0f, 0.0f, 0.0f);
        if (b != vmax) store_normal(v + std::size_t(layout.bottom_pole(b)) * 6, 0.0f, 0.0f, 0.0f);
    }
}

// Every step is per-element IEEE arithmetic (no FMA), so both builds give the same bytes.
RIVULET_AVX2 void cylinder_normals_avx2(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                                        std::uint32_t first, std::uint32_t last, std::span<float> vertices) {
    cylinder_normals_body(layout, vmin, vmax, first, last, vertices);
}

}  // namespace

void cylinder_normals(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                      std::uint32_t first, std::uint32_t last, std::span<float> vertices) {
    if (cpu_has_avx2())
        cylinder_normals_avx2(layout, vmin, vmax, first, last, vertices);
    else
        cylinder_normals_body(layout, vmin, vmax, first, last, vertices);
}

}  // namespace rivulet
