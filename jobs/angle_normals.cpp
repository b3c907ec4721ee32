#include "jobs/angle_normals.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/vector_lanes.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rivulet {
namespace {

// L triangles at once (GCC/Clang vector extensions: 4 lanes in the x86-64 baseline build, 8 in the AVX2
// build): every lane performs the same float operations in the same order, so a triangle's values do not
// depend on its lane, its neighbours or L; the adds into the accumulators run one vertex at a time, in
// triangle order.
using f4 = VectorLanes<4>::f;

// Helpers on L-lane vectors take and give them by reference: no 32-byte vector crosses a function
// boundary of the baseline build (they are all inlined into their caller's build anyway).
template <class F, class I>
RIVULET_INLINE void blend(const I& m, const F& a, const F& b, F& out) {
    out = reinterpret_cast<F>((m & reinterpret_cast<I>(a)) | (~m & reinterpret_cast<I>(b)));
}

// atan2(y, x) for y > 0, in (0, pi): the angle between two edges from |u x w| and u . w. std::atan2 cost
// three quarters of the normals job; this is an octant reduction to [0, 1] and the odd polynomial of
// Abramowitz & Stegun 4.4.49, evaluated in Estrin's form (error 3.5e-7 rad in float, measured against double
// atan2), plain float operations in a fixed order, so the result is deterministic like the rest of the sum.
template <class F, class I>
RIVULET_INLINE void edge_angle(const F& y, const F& x, F& angle) {
    const F ax = reinterpret_cast<F>(reinterpret_cast<I>(x) & 0x7fffffff);
    const I steep = y > ax;
    F lo, hi;
    blend<F, I>(y < ax, y, ax, lo), blend<F, I>(ax < y, y, ax, hi);  // std::min, std::max
    const F t = lo / hi, t2 = t * t;
    // Estrin's scheme: the same polynomial in t2 as pairs, then pairs of pairs, so its dependency chain is
    // four multiplies and adds deep instead of Horner's fourteen.
    const F t4 = t2 * t2, t8 = t4 * t4;
    const F p01 = (t2 * -0.3332985605f) + 0.9999993329f, p23 = (t2 * -0.1390853351f) + 0.1994653599f;
    const F p45 = (t2 * -0.0559098861f) + 0.0964200441f, p67 = (t2 * -0.0040540580f) + 0.0218612288f;
    const F poly = (p01 + p23 * t4) + (p45 + p67 * t4) * t8;
    F a = t * poly;
    blend<F, I>(steep, 1.57079632679f - a, a, a);
    blend<F, I>(x < 0.0f, 3.14159265359f - a, a, angle);
}

RIVULET_INLINE f4 load4(const float* p) {
    f4 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
RIVULET_INLINE void store4(float* p, f4 v) {
    std::memcpy(p, &v, sizeof v);
}
RIVULET_INLINE f4 sqrt4(f4 x) {
#if defined(__SSE2__)
    return _mm_sqrt_ps(x);  // correctly rounded per lane, as std::sqrt
#else
    return f4{std::sqrt(x[0]), std::sqrt(x[1]), std::sqrt(x[2]), std::sqrt(x[3])};
#endif
}
// Quarter h (lanes 4h .. 4h + 3) of an L-lane vector, and the vector from its quarters.
template <class F>
RIVULET_INLINE f4 quarter(const F& v, int h) {
    if constexpr (sizeof(F) == sizeof(f4)) {
        return v;
    } else {
        return h == 0 ? __builtin_shufflevector(v, v, 0, 1, 2, 3) : __builtin_shufflevector(v, v, 4, 5, 6, 7);
    }
}
template <class F>
RIVULET_INLINE void from_quarters(const f4* q, F& v) {
    if constexpr (sizeof(F) == sizeof(f4))
        v = q[0];
    else
        v = __builtin_shufflevector(q[0], q[1], 0, 1, 2, 3, 4, 5, 6, 7);
}
// Rows r[l] = (x, y, z, pad) of four vertices as the columns x, y, z.
RIVULET_INLINE void transpose_in(const f4* r, f4 out[3]) {
    const f4 xy01 = __builtin_shufflevector(r[0], r[1], 0, 4, 1, 5);  // x0 x1 y0 y1
    const f4 xy23 = __builtin_shufflevector(r[2], r[3], 0, 4, 1, 5);
    const f4 zw01 = __builtin_shufflevector(r[0], r[1], 2, 6, 3, 7);  // z0 z1 w0 w1
    const f4 zw23 = __builtin_shufflevector(r[2], r[3], 2, 6, 3, 7);
    out[0] = __builtin_shufflevector(xy01, xy23, 0, 1, 4, 5);
    out[1] = __builtin_shufflevector(xy01, xy23, 2, 3, 6, 7);
    out[2] = __builtin_shufflevector(zw01, zw23, 0, 1, 4, 5);
}
// Columns x, y, z of four lanes as rows (x, y, z, 0), one per lane.
RIVULET_INLINE void transpose_out(f4 x, f4 y, f4 z, f4* out) {
    const f4 zero = {};
    const f4 xy01 = __builtin_shufflevector(x, y, 0, 4, 1, 5);  // x0 y0 x1 y1
    const f4 xy23 = __builtin_shufflevector(x, y, 2, 6, 3, 7);
    const f4 z01 = __builtin_shufflevector(z, zero, 0, 4, 1, 5);  // z0 0 z1 0
    const f4 z23 = __builtin_shufflevector(z, zero, 2, 6, 3, 7);
    out[0] = __builtin_shufflevector(xy01, z01, 0, 1, 4, 5);
    out[1] = __builtin_shufflevector(xy01, z01, 2, 3, 6, 7);
    out[2] = __builtin_shufflevector(xy23, z23, 0, 1, 4, 5);
    out[3] = __builtin_shufflevector(xy23, z23, 2, 3, 6, 7);
}

// Triangles v[3 l .. 3 l + 2] for lanes l < L; p and acc hold four floats per vertex, so a corner is one
// 16-byte load and one 16-byte add. A zero-area lane adds +0, which changes no sum (a sum that starts at
// +0 is never -0).
template <int L>
RIVULET_INLINE void accumulate_lanes(const float* p, const std::uint32_t* v, float* acc) {
    using F = typename VectorLanes<L>::f;
    using I = typename VectorLanes<L>::i;
    constexpr int Q = L / 4;
    F q[3][3];  // q[a][c]: coordinate c of corner a, all lanes
    for (int a = 0; a < 3; ++a) {
        f4 rows[L], cols[3][Q];
        for (int l = 0; l < L; ++l) rows[l] = load4(p + 4 * std::size_t(v[3 * l + a]));
        for (int h = 0; h < Q; ++h) {
            f4 t[3];
            transpose_in(rows + 4 * h, t);
            for (int c = 0; c < 3; ++c) cols[c][h] = t[c];
        }
        for (int c = 0; c < 3; ++c) from_quarters(cols[c], q[a][c]);
    }
    const F e1[3] = {q[1][0] - q[0][0], q[1][1] - q[0][1], q[1][2] - q[0][2]};
    const F e2[3] = {q[2][0] - q[0][0], q[2][1] - q[0][1], q[2][2] - q[0][2]};
    const F c[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0]};
    const F len2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    f4 len_q[Q];
    for (int h = 0; h < Q; ++h) len_q[h] = sqrt4(quarter(len2, h));
    F len;
    from_quarters(len_q, len);
    const I live = len > 0.0f;
    const F inv = 1.0f / len;  // dead lanes (len 0) are masked below
    const F nrm[3] = {c[0] * inv, c[1] * inv, c[2] * inv};
    f4 add[3][L];  // add[a][l]: what corner a of lane l adds to its vertex, as (x, y, z, 0)
    // The angles at corners 0 and 1 by atan2; the angle at corner 2 is what is left of pi (a triangle's
    // angles sum to pi), which saves a third of the division and polynomial work.
    F angle[3];
    for (int a = 0; a < 2; ++a) {
        const F* o = q[a];
        const F* b = q[(a + 1) % 3];
        const F* d = q[(a + 2) % 3];
        const F u[3] = {b[0] - o[0], b[1] - o[1], b[2] - o[2]};
        const F w[3] = {d[0] - o[0], d[1] - o[1], d[2] - o[2]};
        edge_angle<F, I>(len, u[0] * w[0] + u[1] * w[1] + u[2] * w[2], angle[a]);
    }
    angle[2] = (3.14159265359f - angle[0]) - angle[1];
    for (int a = 0; a < 3; ++a) {
        F col[3];
        for (int k = 0; k < 3; ++k)
            col[k] = reinterpret_cast<F>(reinterpret_cast<I>(angle[a] * nrm[k]) & live);
        for (int h = 0; h < Q; ++h)
            transpose_out(quarter(col[0], h), quarter(col[1], h), quarter(col[2], h), add[a] + 4 * h);
    }
    for (int l = 0; l < L; ++l)
        for (int a = 0; a < 3; ++a) {
            float* out = acc + 4 * std::size_t(v[3 * l + a]);
            store4(out, load4(out) + add[a][l]);
        }
}

template <int L>
RIVULET_INLINE void accumulate_body(std::span<const float> p, std::span<const std::uint32_t> tri,
                                    std::span<float> acc) {
    const std::size_t count = tri.size() / 3;
    std::size_t t = 0;
    for (; t + L <= count; t += L) accumulate_lanes<L>(p.data(), tri.data() + t * 3, acc.data());
    if (t < count) {
        // The last triangles, padded with zero-area ones (a vertex they use, three times: it has a
        // position and a zeroed sum, to which they add +0).
        std::uint32_t tail[3 * L];
        std::fill(tail, tail + 3 * L, tri[t * 3]);
        std::copy(tri.data() + t * 3, tri.data() + count * 3, tail);
        accumulate_lanes<L>(p.data(), tail, acc.data());
    }
}

[[gnu::flatten]] RIVULET_AVX2 void accumulate_avx2(std::span<const float> p,
                                                   std::span<const std::uint32_t> tri, std::span<float> acc) {
    accumulate_body<8>(p, tri, acc);
}

}  // namespace

void accumulate_angle_normals(std::span<const float> p, std::span<const std::uint32_t> tri,
                              std::span<float> acc) {
    if (cpu_has_avx2())
        accumulate_avx2(p, tri, acc);
    else
        accumulate_angle_normals_baseline(p, tri, acc);
}

void accumulate_angle_normals_baseline(std::span<const float> p, std::span<const std::uint32_t> tri,
                                       std::span<float> acc) {
    accumulate_body<4>(p, tri, acc);
}

void normalize_or_up(float* n) {
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (len > 0.0f) {
        n[0] /= len, n[1] /= len, n[2] /= len;
    } else {
        n[0] = 0.0f, n[1] = 1.0f, n[2] = 0.0f;
    }
}

void write_vertices(std::span<const float> p, std::span<const float> acc, std::span<float> out) {
    const std::size_t count = out.size() / 6;
    for (std::size_t v = 0; v < count; ++v) {
        float* const o = out.data() + v * 6;
        o[0] = p[v * 4], o[1] = p[v * 4 + 1], o[2] = p[v * 4 + 2];
        o[3] = acc[v * 4], o[4] = acc[v * 4 + 1], o[5] = acc[v * 4 + 2];
        normalize_or_up(o + 3);
    }
}

}  // namespace rivulet
