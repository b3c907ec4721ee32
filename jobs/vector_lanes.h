#pragma once
// GCC/Clang vector types of L float lanes and as many 32-bit integer lanes (comparison results and masks;
// unsigned ones where arithmetic must wrap): four (SSE2, the x86-64 baseline) or eight (one AVX2 register,
// in functions built for AVX2; elsewhere the compiler splits them). Every operation on them is the scalar
// operation per lane.
#include <cmath>
#include <cstdint>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace rivulet {

template <int L>
struct VectorLanes;
template <>
struct VectorLanes<4> {
    using f = float __attribute__((vector_size(16)));
    using i = std::int32_t __attribute__((vector_size(16)));
    using u = std::uint32_t __attribute__((vector_size(16)));
};
template <>
struct VectorLanes<8> {
    using f = float __attribute__((vector_size(32)));
    using i = std::int32_t __attribute__((vector_size(32)));
    using u = std::uint32_t __attribute__((vector_size(32)));
};

// Square root per lane, correctly rounded as std::sqrt (sqrtps); eight lanes as two halves, and the
// result by reference, so that no 32-byte vector crosses a function boundary of a baseline build.
[[gnu::always_inline]] inline void lane_sqrt(const VectorLanes<4>::f& x, VectorLanes<4>::f& r) {
#if defined(__SSE2__)
    r = _mm_sqrt_ps(x);
#else
    for (int k = 0; k < 4; ++k) r[k] = std::sqrt(x[k]);
#endif
}
[[gnu::always_inline]] inline void lane_sqrt(const VectorLanes<8>::f& x, VectorLanes<8>::f& r) {
    VectorLanes<4>::f lo, hi;
    lane_sqrt(__builtin_shufflevector(x, x, 0, 1, 2, 3), lo);
    lane_sqrt(__builtin_shufflevector(x, x, 4, 5, 6, 7), hi);
    r = __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
}

// Bit l set where lane l of a comparison result (all ones or zero per lane) is set: the lanes' sign bits
// (movmskps), eight lanes as two halves as in lane_sqrt.
[[gnu::always_inline]] inline unsigned lane_bits(const VectorLanes<4>::i& m) {
#if defined(__SSE2__)
    return static_cast<unsigned>(_mm_movemask_ps(_mm_castsi128_ps(__m128i(m))));
#else
    unsigned b = 0;
    for (int k = 0; k < 4; ++k) b |= unsigned(m[k] < 0) << k;
    return b;
#endif
}
[[gnu::always_inline]] inline unsigned lane_bits(const VectorLanes<8>::i& m) {
    return lane_bits(VectorLanes<4>::i(__builtin_shufflevector(m, m, 0, 1, 2, 3))) |
           lane_bits(VectorLanes<4>::i(__builtin_shufflevector(m, m, 4, 5, 6, 7))) << 4;
}

}  // namespace rivulet
