#include "jobs/weld_indices.h"

#include <cstring>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "jobs/cpu_dispatch.h"
#include "jobs/vector_lanes.h"

namespace rivulet {
namespace {

RIVULET_INLINE std::uint32_t weld_one(std::uint32_t v, const BlockVertexMap& map) {
    return v < map.owned ? map.offset + v : map.foreign[map.top - v];
}

// Whether any lane of a comparison result is set.
#if defined(__SSE2__)
RIVULET_INLINE bool any_lane(VectorLanes<4>::i m) {
    return _mm_movemask_ps(reinterpret_cast<__m128>(m)) != 0;
}
// By reference: a 32-byte vector passed by value to a function without the AVX target changes the ABI
// (clang's -Wpsabi), although it is always inlined into the AVX2 build.
RIVULET_INLINE bool any_lane(const VectorLanes<8>::i& m) {  // the halves or'ed: an SSE movemask suffices
    return any_lane(__builtin_shufflevector(m, m, 0, 1, 2, 3) | __builtin_shufflevector(m, m, 4, 5, 6, 7));
}
#else
template <class I>
RIVULET_INLINE bool any_lane(I m) {
    bool any = false;
    for (std::size_t l = 0; l < sizeof m / sizeof m[0]; ++l) any |= m[l] != 0;
    return any;
}
#endif

// L indices at a time: most runs of L corners name owned vertices only (foreign vertices lie on the
// block's max faces), and those are one compare and one add a vector; a run with a foreign corner goes
// one at a time.
template <int L>
RIVULET_INLINE void weld_body(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                              std::span<std::uint32_t> out) {
    using I = typename VectorLanes<L>::i;
    using U = typename VectorLanes<L>::u;
    const std::size_t count = local.size();
    // Block vertex numbers stay below 2^31 (a block holds far fewer), so signed lanes compare them
    // correctly; mesh indices may not, so the offset is added to unsigned lanes.
    const I owned = I{} + static_cast<std::int32_t>(map.owned);
    const U offset = U{} + map.offset;
    std::size_t t = 0;
    for (; t + L <= count; t += L) {
        I v;
        std::memcpy(&v, local.data() + t, sizeof v);
        if (!any_lane(v >= owned)) {
            const U w = reinterpret_cast<U>(v) + offset;
            std::memcpy(out.data() + t, &w, sizeof w);
            continue;
        }
        for (int l = 0; l < L; ++l) out[t + std::size_t(l)] = weld_one(local[t + std::size_t(l)], map);
    }
    for (; t < count; ++t) out[t] = weld_one(local[t], map);
}

[[gnu::flatten]] RIVULET_AVX2 void weld_avx2(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                                             std::span<std::uint32_t> out) {
    weld_body<8>(local, map, out);
}

}  // namespace

void weld_indices(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                  std::span<std::uint32_t> out) {
    if (cpu_has_avx2())
        weld_avx2(local, map, out);
    else
        weld_indices_baseline(local, map, out);
}

void weld_indices_baseline(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                           std::span<std::uint32_t> out) {
    weld_body<4>(local, map, out);
}

}  // namespace rivulet
