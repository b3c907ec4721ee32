#pragma once
// Four floats at a time, for the few kernels whose loops the compiler will not vectorize by itself
// (early-exit searches that need a hit mask, gathered neighbours). SSE2 is part of x86-64, so no -march flag
// is needed; other targets get the same results from the scalar fallback. Every operation is an exactly
// rounded IEEE operation per lane, so results are the same bytes either way.
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rivulet::simd {

#if defined(__SSE2__)

struct F4 {
    __m128 v;
};
inline F4 load(const float* p) {
    return {_mm_loadu_ps(p)};
}
inline F4 splat(float x) {
    return {_mm_set1_ps(x)};
}
// Lanes 0-3 from four scalars (gathered neighbours).
inline F4 make(float a, float b, float c, float d) {
    return {_mm_setr_ps(a, b, c, d)};
}
inline F4 operator+(F4 a, F4 b) {
    return {_mm_add_ps(a.v, b.v)};
}
inline F4 operator-(F4 a, F4 b) {
    return {_mm_sub_ps(a.v, b.v)};
}
inline F4 operator*(F4 a, F4 b) {
    return {_mm_mul_ps(a.v, b.v)};
}
inline F4 operator/(F4 a, F4 b) {
    return {_mm_div_ps(a.v, b.v)};
}
inline F4 sqrt(F4 a) {
    return {_mm_sqrt_ps(a.v)};
}
// Per lane: if_le where a <= b, else otherwise.
inline F4 select_le(F4 a, F4 b, F4 if_le, F4 otherwise) {
    const __m128 m = _mm_cmple_ps(a.v, b.v);
    return {_mm_or_ps(_mm_and_ps(m, if_le.v), _mm_andnot_ps(m, otherwise.v))};
}
// Bit k set where lane k of a is less than lane k of b.
inline unsigned less_mask(F4 a, F4 b) {
    return static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(a.v, b.v)));
}
inline void store(float* p, F4 a) {
    _mm_storeu_ps(p, a.v);
}
// The four lanes' sum in a fixed order: (l0 + l1) + (l2 + l3).
inline float sum(F4 a) {
    alignas(16) float l[4];
    _mm_store_ps(l, a.v);
    return (l[0] + l[1]) + (l[2] + l[3]);
}
// Lane-wise max; b where a is NaN, as maxps.
inline F4 max(F4 a, F4 b) {
    return {_mm_max_ps(a.v, b.v)};
}
// The x, y and z columns of four packed records (x, y, z, w), w dropped: four neighbours' positions or
// velocities from four loads instead of twelve.
inline void columns3(F4 r0, F4 r1, F4 r2, F4 r3, F4& x, F4& y, F4& z) {
    const __m128 xy01 = _mm_unpacklo_ps(r0.v, r1.v), xy23 = _mm_unpacklo_ps(r2.v, r3.v);
    const __m128 zw01 = _mm_unpackhi_ps(r0.v, r1.v), zw23 = _mm_unpackhi_ps(r2.v, r3.v);
    x = {_mm_movelh_ps(xy01, xy23)}, y = {_mm_movehl_ps(xy23, xy01)}, z = {_mm_movelh_ps(zw01, zw23)};
}

#else

struct F4 {
    float v[4];
};
inline F4 load(const float* p) {
    return {{p[0], p[1], p[2], p[3]}};
}
inline F4 splat(float x) {
    return {{x, x, x, x}};
}
inline F4 make(float a, float b, float c, float d) {
    return {{a, b, c, d}};
}
inline float sum(F4 a) {
    return (a.v[0] + a.v[1]) + (a.v[2] + a.v[3]);
}
inline F4 operator+(F4 a, F4 b) {
    return {{a.v[0] + b.v[0], a.v[1] + b.v[1], a.v[2] + b.v[2], a.v[3] + b.v[3]}};
}
inline F4 operator-(F4 a, F4 b) {
    return {{a.v[0] - b.v[0], a.v[1] - b.v[1], a.v[2] - b.v[2], a.v[3] - b.v[3]}};
}
inline F4 operator*(F4 a, F4 b) {
    return {{a.v[0] * b.v[0], a.v[1] * b.v[1], a.v[2] * b.v[2], a.v[3] * b.v[3]}};
}
inline F4 operator/(F4 a, F4 b) {
    return {{a.v[0] / b.v[0], a.v[1] / b.v[1], a.v[2] / b.v[2], a.v[3] / b.v[3]}};
}
inline F4 sqrt(F4 a) {
    return {{std::sqrt(a.v[0]), std::sqrt(a.v[1]), std::sqrt(a.v[2]), std::sqrt(a.v[3])}};
}
inline F4 select_le(F4 a, F4 b, F4 if_le, F4 otherwise) {
    F4 r;
    for (unsigned k = 0; k < 4; ++k) r.v[k] = a.v[k] <= b.v[k] ? if_le.v[k] : otherwise.v[k];
    return r;
}
inline unsigned less_mask(F4 a, F4 b) {
    unsigned m = 0;
    for (unsigned k = 0; k < 4; ++k) m |= static_cast<unsigned>(a.v[k] < b.v[k]) << k;
    return m;
}
inline void store(float* p, F4 a) {
    for (unsigned k = 0; k < 4; ++k) p[k] = a.v[k];
}
inline F4 max(F4 a, F4 b) {
    return {{a.v[0] > b.v[0] ? a.v[0] : b.v[0], a.v[1] > b.v[1] ? a.v[1] : b.v[1],
             a.v[2] > b.v[2] ? a.v[2] : b.v[2], a.v[3] > b.v[3] ? a.v[3] : b.v[3]}};
}
inline void columns3(F4 r0, F4 r1, F4 r2, F4 r3, F4& x, F4& y, F4& z) {
    x = {{r0.v[0], r1.v[0], r2.v[0], r3.v[0]}};
    y = {{r0.v[1], r1.v[1], r2.v[1], r3.v[1]}};
    z = {{r0.v[2], r1.v[2], r2.v[2], r3.v[2]}};
}

#endif

// Squared distances from (qx, qy, qz) to points p[0..3] below eps2, as a 4-bit mask.
inline unsigned near_mask(const float* px, const float* py, const float* pz, F4 qx, F4 qy, F4 qz, F4 eps2) {
    const F4 dx = load(px) - qx, dy = load(py) - qy, dz = load(pz) - qz;
    return less_mask(dx * dx + dy * dy + dz * dz, eps2);
}

}  // namespace rivulet::simd
