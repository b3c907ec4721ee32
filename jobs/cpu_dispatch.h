#pragma once
// A few kernels are compiled twice, for the x86-64 baseline (SSE2) and for AVX2, and the AVX2 build runs
// when the CPU has it; the release build itself needs no -march flag and runs anywhere. Both builds do
// the same IEEE operations per element in the same order (no FMA: -ffp-contract=off, and the AVX2
// target does not enable it), so they give the same bytes.
//
//   RIVULET_AVX2 void kernel_avx2(args) { kernel_body(args); }       // body: an always-inline function
//   void kernel(args) { if (cpu_has_avx2()) kernel_avx2(args); else kernel_body(args); }
//
// A function the AVX2 body calls out of line needs an AVX2 build of its own (or RIVULET_OPAQUE, so the
// caller clears the vectors' upper halves first): GCC sees which registers a baseline function of the
// same file uses and keeps the caller's vectors live in the others across the call, and on Intel each
// of that function's SSE instructions then pays for the mixed state (the diffuse update ran 2.4 times
// as long; jobs/diffuse_update.cpp).
//
// RIVULET_NO_AVX2=1 in the environment forces the baseline builds (tests compare the two).
#include <cstdlib>

#if defined(__x86_64__) && defined(__GNUC__)
#define RIVULET_AVX2 __attribute__((target("avx2")))
#if defined(__clang__)
#define RIVULET_OPAQUE [[gnu::noinline]]
#else
#define RIVULET_OPAQUE [[gnu::noinline, gnu::noipa]]
#endif
#define RIVULET_INLINE [[gnu::always_inline]] inline
namespace rivulet {
inline bool cpu_has_avx2() {
    static const bool has = __builtin_cpu_supports("avx2") && std::getenv("RIVULET_NO_AVX2") == nullptr;
    return has;
}
}  // namespace rivulet
#else
#define RIVULET_AVX2
#define RIVULET_OPAQUE
#define RIVULET_INLINE inline
namespace rivulet {
inline bool cpu_has_avx2() {
    return false;
}
}  // namespace rivulet
#endif
