#include "jobs/angle_normals.h"

#include <algorithm>
#include <cmath>

namespace rivulet {
namespace {

// Four triangles at once (GCC/Clang vector extensions): every lane performs the same float operations
// in the same order, so a triangle's values do not depend on its lane or on its neighbours; only the adds
// into the accumulators are scalar, in triangle order.
using f4 = float __attribute__((vector_size(16)));
using i4 = std::int32_t __attribute__((vector_size(16)));

f4 select(i4 m, f4 a, f4 b) {
    return reinterpret_cast<f4>((m & reinterpret_cast<i4>(a)) | (~m & reinterpret_cast<i4>(b)));
}

// atan2(y, x) for y > 0, in (0, pi): the angle between two edges from |u x w| and u . w. std::atan2 cost
// three quarters of the normals job; this is an octant reduction to [0, 1] and the odd polynomial of
// Abramowitz & Stegun 4.4.49 (error 3e-7 rad in float, measured against double atan2), plain float
// operations in a fixed order, so the result is deterministic like the rest of the sum.
f4 edge_angle4(f4 y, f4 x) {
    const f4 ax = reinterpret_cast<f4>(reinterpret_cast<i4>(x) & 0x7fffffff);
    const i4 steep = y > ax;
    const f4 t = select(y < ax, y, ax) / select(ax < y, y, ax);  // std::min / std::max
    const f4 t2 = t * t;
    f4 poly = {-0.0040540580f, -0.0040540580f, -0.0040540580f, -0.0040540580f};
    poly = poly * t2 + 0.0218612288f;
    poly = poly * t2 - 0.0559098861f;
    poly = poly * t2 + 0.0964200441f;
    poly = poly * t2 - 0.1390853351f;
    poly = poly * t2 + 0.1994653599f;
    poly = poly * t2 - 0.3332985605f;
    poly = poly * t2 + 0.9999993329f;
    f4 a = t * poly;
    a = select(steep, 1.57079632679f - a, a);
    return select(x < 0.0f, 3.14159265359f - a, a);
}

// Triangles v[0..2], v[3..5], v[6..8], v[9..11] (v[3 l + a]: corner a of lane l). A zero-area lane adds
// nothing.
void accumulate_four(std::span<const float> p, const std::uint32_t* v, std::span<float> acc) {
    auto gather = [&](int a, std::size_t c) {  // coordinate c of corner a, all lanes
        auto at = [&](int l) { return p[std::size_t(v[3 * l + a]) * 3 + c]; };
        return f4{at(0), at(1), at(2), at(3)};
    };
    const f4 q[3][3] = {{gather(0, 0), gather(0, 1), gather(0, 2)},
                        {gather(1, 0), gather(1, 1), gather(1, 2)},
                        {gather(2, 0), gather(2, 1), gather(2, 2)}};  // q[a][c]
    const f4 e1[3] = {q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
    const f4 e2[3] = {q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
    const f4 c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                     e1[0] * e2[1] - e1[1] * e2[0]};
    const f4 len2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    const f4 len = {std::sqrt(len2[0]), std::sqrt(len2[1]), std::sqrt(len2[2]), std::sqrt(len2[3])};
    const f4 inv = 1.0f / len;  // unused lanes (len 0) are skipped below
    const f4 nrm[3] = {c[0] * inv, c[1] * inv, c[2] * inv};
    f4 add[3][3];  // add[a][c]: what corner a adds to its vertex
    for (int a = 0; a < 3; ++a) {
        const f4* o = q[a];
        const f4* b = q[(a + 1) % 3];
        const f4* d = q[(a + 2) % 3];
        const f4 u[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
        const f4 w[3] = {d[0] - o[0], d[1] - o[1], d[2] - o[2]};
        const f4 angle = edge_angle4(len, u[0] * w[0] + u[1] * w[1] + u[2] * w[2]);
        for (int k = 0; k < 3; ++k) add[a][k] = angle * nrm[k];
    }
    for (int l = 0; l < 4; ++l) {
        if (!(len[l] > 0.0f)) continue;
        for (int a = 0; a < 3; ++a) {
            float* out = &acc[std::size_t(v[3 * l + a]) * 3];
            out[0] += add[a][0][l], out[1] += add[a][1][l], out[2] += add[a][2][l];
        }
    }
}

}  // namespace

void accumulate_angle_normals(std::span<const float> p, std::span<const std::uint32_t> tri,
                              std::span<float> acc) {
    std::fill(acc.begin(), acc.end(), 0.0f);
    const std::size_t count = tri.size() / 3;
    std::size_t t = 0;
    for (; t + 4 <= count; t += 4) accumulate_four(p, tri.data() + t * 3, acc);
    if (t < count) {
        // The last one to three triangles, padded with zero-area ones (vertex 0 three times).
        std::uint32_t tail[12] = {};
        std::copy(tri.data() + t * 3, tri.data() + count * 3, tail);
        accumulate_four(p, tail, acc);
    }
}

void normalize_or_up(float* n) {
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0f) {
        n[0] /= len, n[1] /= len, n[2] /= len;
    } else {
        n[0] = 0.0f, n[1] = 1.0f, n[2] = 0.0f;
    }
}

}  // namespace rivulet
