#pragma once
// GCC/Clang vector types of L float lanes and as many 32-bit integer lanes (comparison results and masks;
// unsigned ones where arithmetic must wrap): four (SSE2, the x86-64 baseline) or eight (one AVX2 register,
// in functions built for AVX2; elsewhere the compiler splits them). Every operation on them is the scalar
// operation per lane.
#include <cstdint>

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

}  // namespace rivulet
