#include "jobs/dfsph_solve.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/simd4.h"

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace rivulet {

namespace {

// The walls' term of particle i's rate, grad B_i . (v_i - v_wall).
inline float wall_rate(const DfsphContext& c, std::size_t i, const float* v) {
    return c.wall_gx[i] * (v[0] - c.wall_velocity[0]) + c.wall_gy[i] * (v[1] - c.wall_velocity[1]) +
           c.wall_gz[i] * (v[2] - c.wall_velocity[2]);
}

// V grad W_ij of pair q of particle i (at xi): the pair's radial factor times x_i - x_j, the build's
// own product from the same floats.
inline simd::F4 pair_gradient(const DfsphContext& c, simd::F4 xi, const DfsphPair& q) {
    return simd::splat(q.f) * (xi - simd::load(&c.x4[4 * std::size_t(q.j)]));
}

// The sum of term(pair) over particle i's pairs, in list order from +0, four pairs a loop test: the list's
// pad pairs (jobs/dfsph_lists.h) complete the last four, and their zero terms leave the sum's bits.
template <class Term>
inline simd::F4 sum_over_pairs(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                               const Term& term) {
    simd::F4 sum = simd::splat(0.0f);
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; p += 4) {
        const DfsphPair* const q = &l.pairs[p];
        sum = sum + term(q[0]);
        sum = sum + term(q[1]);
        sum = sum + term(q[2]);
        sum = sum + term(q[3]);
    }
    return sum;
}

// sum_j V grad W_ij . (v_i - v_j) over particle i's pairs, plus the walls': the three products summed
// per axis in lanes, the axes added at the end.
inline float rate_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                     std::span<const float> v4) {
    const simd::F4 vi = simd::load(&v4[4 * i]);
    const simd::F4 xi = simd::load(&c.x4[4 * i]);
    const simd::F4 sum = sum_over_pairs(c, l, i, [&](const DfsphPair& q) {
        return pair_gradient(c, xi, q) * (vi - simd::load(&v4[4 * std::size_t(q.j)]));
    });
    alignas(16) float s[4];
    simd::store(s, sum);
    float rate = (s[0] + s[1]) + s[2];
    rate += wall_rate(c, i, &v4[4 * i]);
    return rate;
}

// sum_j (k_i + k_j) V grad W_ij + k_i grad B_i, the velocity change of particle i: the three sums in lanes
// 0-2, each the scalar sum's operations in the same order.
inline void correction_of(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                          std::span<const float> k, float d[3]) {
    const float ki = k[i];
    const simd::F4 xi = simd::load(&c.x4[4 * i]);
    const simd::F4 sum = sum_over_pairs(
        c, l, i, [&](const DfsphPair& q) { return simd::splat(ki + k[q.j]) * pair_gradient(c, xi, q); });
    alignas(16) float lanes[4];
    simd::store(lanes, sum);
    d[0] = lanes[0] + ki * c.wall_gx[i], d[1] = lanes[1] + ki * c.wall_gy[i],
    d[2] = lanes[2] + ki * c.wall_gz[i];
}

// Over particle i's pairs, four to a vector (a pair a lane, their neighbours' packed positions and
// velocities turned into columns; past the list's end its pad pairs (0, i), which add +0): the viscosity's
// sum sum_j (v_ij . x_ij) / (r_ij^2 + eps2) V grad W_ij (Monaghan's form) into a, and the rate sum_j V grad
// W_ij . (v_i - v_j) = sum_j f_ij (v_ij . x_ij), returned. Each lane's sums are added in a fixed order at the
// end.
inline float viscosity_and_rate(const DfsphContext& c, const DfsphChunkLists& l, std::size_t i,
                                std::span<const float> v4, float eps2, float a[3]) {
    using simd::F4;
    const float* const x4 = c.x4.data();
    const float* const v = v4.data();
    const F4 xi = simd::splat(x4[4 * i]), yi = simd::splat(x4[4 * i + 1]), zi = simd::splat(x4[4 * i + 2]);
    const F4 vxi = simd::splat(v[4 * i]), vyi = simd::splat(v[4 * i + 1]), vzi = simd::splat(v[4 * i + 2]);
    const F4 e2 = simd::splat(eps2);
    F4 ax = simd::splat(0.0f), ay = ax, az = ax, rate = ax;
    for (std::uint32_t p = c.pair_begin[i]; p < c.pair_end[i]; p += 4) {
        const DfsphPair& q0 = l.pairs[p];
        const DfsphPair& q1 = l.pairs[p + 1];
        const DfsphPair& q2 = l.pairs[p + 2];
        const DfsphPair& q3 = l.pairs[p + 3];
        const std::size_t j0 = 4 * std::size_t(q0.j), j1 = 4 * std::size_t(q1.j), j2 = 4 * std::size_t(q2.j),
                          j3 = 4 * std::size_t(q3.j);
        F4 xj, yj, zj, vxj, vyj, vzj;
        simd::columns3(simd::load(x4 + j0), simd::load(x4 + j1), simd::load(x4 + j2), simd::load(x4 + j3), xj,
                       yj, zj);
        simd::columns3(simd::load(v + j0), simd::load(v + j1), simd::load(v + j2), simd::load(v + j3), vxj,
                       vyj, vzj);
        const F4 dx = xi - xj, dy = yi - yj, dz = zi - zj;
        const F4 r2 = dx * dx + dy * dy + dz * dz;
        const F4 vr = (vxi - vxj) * dx + (vyi - vyj) * dy + (vzi - vzj) * dz;
        const F4 f = simd::make(q0.f, q1.f, q2.f, q3.f);
        rate = rate + f * vr;
        const F4 s = vr / (r2 + e2);
        ax = ax + s * (f * dx);
        ay = ay + s * (f * dy);
        az = az + s * (f * dz);
    }
    a[0] = simd::sum(ax), a[1] = simd::sum(ay), a[2] = simd::sum(az);
    return simd::sum(rate);
}

#if defined(__x86_64__) && defined(__GNUC__)
// The x, y and z columns of eight packed records, rows k and k + 4 in the two halves of row k: the
// transpose of columns3 on both halves at once.
RIVULET_AVX2 inline void columns3_avx2(__m256 r0, __m256 r1, __m256 r2, __m256 r3, __m256& x, __m256& y,
                                       __m256& z) {
    const __m256 xy01 = _mm256_unpacklo_ps(r0, r1), xy23 = _mm256_unpacklo_ps(r2, r3);
    const __m256 zw01 = _mm256_unpackhi_ps(r0, r1), zw23 = _mm256_unpackhi_ps(r2, r3);
    x = _mm256_shuffle_ps(xy01, xy23, 0x44), y = _mm256_shuffle_ps(xy01, xy23, 0xee);
    z = _mm256_shuffle_ps(zw01, zw23, 0x44);
}

// Records j0 (low half) and j1 (high half) of a packed array as one row.
RIVULET_AVX2 inline __m256 two_records(const float* base, std::size_t j0, std::size_t j1) {
    return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(base + j0)), _mm_loadu_ps(base + j1), 1);
}

// sum + the low half of t, then + its high half.
RIVULET_AVX2 inline void add_halves(__m128& sum, __m256 t) {
    sum = _mm_add_ps(sum, _mm256_castps256_ps128(t));
    sum = _mm_add_ps(sum, _mm256_extractf128_ps(t, 1));
}

// viscosity_and_rate with eight pairs to a vector: the two groups of four in the halves, each half the
// four-lane operations of a group, added to the four-lane sums low half first: the same bytes, with the
// transposes (which bound the four-lane loop on Zen 3's shuffle units) and the arithmetic halved. A list
// with an odd number of groups ends with one group of four.
RIVULET_AVX2 inline float viscosity_and_rate_avx2(const DfsphContext& c, const DfsphChunkLists& l,
                                                  std::size_t i, std::span<const float> v4, float eps2,
                                                  float a[3]) {
    const float* const x4 = c.x4.data();
    const float* const v = v4.data();
    const __m256 xi = _mm256_set1_ps(x4[4 * i]), yi = _mm256_set1_ps(x4[4 * i + 1]),
                 zi = _mm256_set1_ps(x4[4 * i + 2]);
    const __m256 vxi = _mm256_set1_ps(v[4 * i]), vyi = _mm256_set1_ps(v[4 * i + 1]),
                 vzi = _mm256_set1_ps(v[4 * i + 2]);
    const __m256 e2 = _mm256_set1_ps(eps2);
    __m128 ax = _mm_setzero_ps(), ay = ax, az = ax, rate = ax;
    std::uint32_t p = c.pair_begin[i];
    const std::uint32_t end = c.pair_end[i];
    for (; p + 4 < end; p += 8) {  // both groups hold pairs (the list's end is not padded)
        const DfsphPair* const q = &l.pairs[p];
        std::size_t j[8];
        for (int k = 0; k < 8; ++k) j[k] = 4 * std::size_t(q[k].j);
        __m256 xj, yj, zj, vxj, vyj, vzj;
        columns3_avx2(two_records(x4, j[0], j[4]), two_records(x4, j[1], j[5]), two_records(x4, j[2], j[6]),
                      two_records(x4, j[3], j[7]), xj, yj, zj);
        columns3_avx2(two_records(v, j[0], j[4]), two_records(v, j[1], j[5]), two_records(v, j[2], j[6]),
                      two_records(v, j[3], j[7]), vxj, vyj, vzj);
        // The factors: (f0 j0 f1 j1 f2 j2 f3 j3) and the next four, even lanes, halves in order.
        const __m256 p0 = _mm256_loadu_ps(reinterpret_cast<const float*>(q));
        const __m256 p1 = _mm256_loadu_ps(reinterpret_cast<const float*>(q + 4));
        const __m256 f =
            _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(_mm256_shuffle_ps(p0, p1, 0x88)), 0xd8));
        const __m256 dx = _mm256_sub_ps(xi, xj), dy = _mm256_sub_ps(yi, yj), dz = _mm256_sub_ps(zi, zj);
        const __m256 r2 =
            _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
        const __m256 vr = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(vxi, vxj), dx),
                                                      _mm256_mul_ps(_mm256_sub_ps(vyi, vyj), dy)),
                                        _mm256_mul_ps(_mm256_sub_ps(vzi, vzj), dz));
        add_halves(rate, _mm256_mul_ps(f, vr));
        const __m256 s = _mm256_div_ps(vr, _mm256_add_ps(r2, e2));
        const __m256 tx = _mm256_mul_ps(s, _mm256_mul_ps(f, dx)), ty = _mm256_mul_ps(s, _mm256_mul_ps(f, dy)),
                     tz = _mm256_mul_ps(s, _mm256_mul_ps(f, dz));
        // Each sum takes its low half, then its high half: pair order, as the four-lane loop.
        add_halves(ax, tx), add_halves(ay, ty), add_halves(az, tz);
    }
    if (p < end) {  // the last group of four, as viscosity_and_rate's loop
        const DfsphPair* const q = &l.pairs[p];
        const std::size_t j0 = 4 * std::size_t(q[0].j), j1 = 4 * std::size_t(q[1].j),
                          j2 = 4 * std::size_t(q[2].j), j3 = 4 * std::size_t(q[3].j);
        simd::F4 xj, yj, zj, vxj, vyj, vzj;
        simd::columns3(simd::load(x4 + j0), simd::load(x4 + j1), simd::load(x4 + j2), simd::load(x4 + j3), xj,
                       yj, zj);
        simd::columns3(simd::load(v + j0), simd::load(v + j1), simd::load(v + j2), simd::load(v + j3), vxj,
                       vyj, vzj);
        const simd::F4 lo_x{_mm256_castps256_ps128(xi)}, lo_y{_mm256_castps256_ps128(yi)},
            lo_z{_mm256_castps256_ps128(zi)};
        const simd::F4 lo_vx{_mm256_castps256_ps128(vxi)}, lo_vy{_mm256_castps256_ps128(vyi)},
            lo_vz{_mm256_castps256_ps128(vzi)};
        const simd::F4 dx = lo_x - xj, dy = lo_y - yj, dz = lo_z - zj;
        const simd::F4 r2 = dx * dx + dy * dy + dz * dz;
        const simd::F4 vr = (lo_vx - vxj) * dx + (lo_vy - vyj) * dy + (lo_vz - vzj) * dz;
        const simd::F4 f = simd::make(q[0].f, q[1].f, q[2].f, q[3].f);
        rate = (simd::F4{rate} + f * vr).v;
        const simd::F4 s4 = vr / (r2 + simd::splat(eps2));
        ax = (simd::F4{ax} + s4 * (f * dx)).v;
        ay = (simd::F4{ay} + s4 * (f * dy)).v;
        az = (simd::F4{az} + s4 * (f * dz)).v;
    }
    a[0] = simd::sum({ax}), a[1] = simd::sum({ay}), a[2] = simd::sum({az});
    return simd::sum({rate});
}
#endif

// A residual's new total: relaxed Jacobi's max(k_total + omega r alpha, 0), or with Chebyshev weight
// w != 1 that extrapolated from the total an iteration back (k_total - k: k still holds the change last
// applied), clamped at 0 again. The change goes to k; returns the error's share max(r, 0) dt.
inline double relax(float r, float dt, float factor, float k_total, float& k, float w) {
    const float step = k_total + kDfsphRelaxation * r * factor;
    float total = step > 0.0f ? step : 0.0f;
    if (w != 1.0f) {
        const float before = k_total - k;
        const float extrapolated = before + w * (total - before);
        total = extrapolated > 0.0f ? extrapolated : 0.0f;
    }
    k = total - k_total;
    return r > 0.0f ? double(r) * dt : 0.0;
}

// The divergence solve's residual of particle i from its rate, relaxed into check.k; a particle with
// under min_support (a surface particle, whose deficient density would read as expansion) counts 0.
inline double relax_divergence(const DfsphContext& c, std::size_t i, float rate, float dt,
                               const DfsphDivergenceCheck& check, float w) {
    const float r = c.support[i] >= c.min_support ? rate : 0.0f;
    return relax(r, dt, check.factor[i], check.k_total[i], check.k[i], w);
}

// sum_i error(i, rate_i) over particles [begin, end) in order, the rates of a block of particles first:
// the pair loops run back to back, and the residuals' serial arithmetic (a division, the clamps) then
// pipelines across the block instead of waiting behind each list's loop exit. The same operations in the
// same order; a seventh off the density residual pass (perf/RESULTS.md). The correction and the
// prediction, whose per-particle tails are short or overlap their second pair loop, gained nothing so.
template <class Error>
RIVULET_INLINE double sum_over_rates(const DfsphContext& c, std::size_t chunk, std::size_t begin,
                                     std::size_t end, std::span<const float> v4, const Error& error) {
    const DfsphChunkLists& l = c.lists[chunk];
    constexpr std::size_t kBlock = 64;
    float rate[kBlock];
    double sum = 0.0;
    for (std::size_t first = begin; first < end; first += kBlock) {
        const std::size_t n = end - first < kBlock ? end - first : kBlock;
        for (std::size_t m = 0; m < n; ++m) rate[m] = rate_of(c, l, first + m, v4);
        for (std::size_t m = 0; m < n; ++m) sum += error(first + m, rate[m]);
    }
    return sum;
}

RIVULET_INLINE double divergence_residual_pass(const DfsphContext& c, std::size_t chunk, std::size_t begin,
                                               std::size_t end, float dt, std::span<const float> v4,
                                               const DfsphDivergenceCheck& check, float chebyshev) {
    return sum_over_rates(c, chunk, begin, end, v4, [&](std::size_t i, float rate) {
        return relax_divergence(c, i, rate, dt, check, chebyshev);
    });
}

RIVULET_INLINE double residual_pass(const DfsphContext& c, std::size_t chunk, std::size_t begin,
                                    std::size_t end, float dt, std::span<const float> v4,
                                    std::span<const float> density_ratio, std::span<const float> factor,
                                    std::span<const float> k_total, std::span<float> k, float catch_up,
                                    float chebyshev) {
    return sum_over_rates(c, chunk, begin, end, v4, [&](std::size_t i, float rate) {
        const float r = ((density_ratio[i] - 1.0f) * catch_up + dt * rate) / dt;  // signed, per second
        return relax(r, dt, factor[i], k_total[i], k[i], chebyshev);
    });
}

RIVULET_INLINE void correct_pass(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                                 std::span<const float> k, const DfsphVelocities& v) {
    const DfsphChunkLists& l = c.lists[chunk];
    for (std::size_t i = begin; i < end; ++i) {
        float d[3];
        correction_of(c, l, i, k, d);
        const float vx = v.vx[i] - d[0], vy = v.vy[i] - d[1], vz = v.vz[i] - d[2];
        v.vx[i] = vx, v.vy[i] = vy, v.vz[i] = vz;
        v.v4[4 * i] = vx, v.v4[4 * i + 1] = vy, v.v4[4 * i + 2] = vz;
    }
}

template <bool kAvx2>
RIVULET_INLINE DfsphPredictSums predict_pass(const DfsphContext& c, std::size_t chunk, std::size_t begin,
                                             std::size_t end, float dt, float nu, float h,
                                             const float gravity[3], std::span<const float> v4,
                                             std::span<const float> k_warm, const DfsphDivergenceCheck& check,
                                             const DfsphVelocities& out) {
    const DfsphChunkLists& l = c.lists[chunk];
    const float eps2 = 0.01f * h * h;
    const float scale = 10.0f * nu;
    DfsphPredictSums sums;
    for (std::size_t i = begin; i < end; ++i) {
        const float* const vi = &v4[4 * i];
        float a[3];
        float rate = 0.0f;
#if defined(__x86_64__) && defined(__GNUC__)
        if constexpr (kAvx2)
            rate = viscosity_and_rate_avx2(c, l, i, v4, eps2, a);
        else
#endif
            rate = viscosity_and_rate(c, l, i, v4, eps2, a);
        rate += wall_rate(c, i, vi);
        sums.divergence_error += relax_divergence(c, i, rate, dt, check, 1.0f);  // the solve's first look
        const float px = vi[0] + dt * (a[0] * scale + gravity[0]);
        const float py = vi[1] + dt * (a[1] * scale + gravity[1]);
        const float pz = vi[2] + dt * (a[2] * scale + gravity[2]);
        const float v2 = px * px + py * py + pz * pz;
        if (v2 > sums.max_v2) sums.max_v2 = v2;
        float d[3];
        correction_of(c, l, i, k_warm, d);  // the pairs again, while they are in cache
        const float ox = px - d[0], oy = py - d[1], oz = pz - d[2];
        out.vx[i] = ox, out.vy[i] = oy, out.vz[i] = oz;
        out.v4[4 * i] = ox, out.v4[4 * i + 1] = oy, out.v4[4 * i + 2] = oz, out.v4[4 * i + 3] = 0.0f;
    }
    return sums;
}

#if defined(__x86_64__) && defined(__GNUC__)
// The passes again for AVX2 CPUs: the same four-lane operations in the same order (so the same bytes),
// VEX-encoded. The pair loops are bound by instruction issue, not by their additions' latency or by
// memory; there a pair's factor is broadcast by its load and no register is copied for a two-operand
// form, 11 instructions a pair instead of 16, and the passes take about a sixth less time.
[[gnu::flatten]] RIVULET_AVX2 double divergence_residual_avx2(const DfsphContext& c, std::size_t chunk,
                                                              std::size_t begin, std::size_t end, float dt,
                                                              std::span<const float> v4,
                                                              const DfsphDivergenceCheck& check,
                                                              float chebyshev) {
    return divergence_residual_pass(c, chunk, begin, end, dt, v4, check, chebyshev);
}
[[gnu::flatten]] RIVULET_AVX2 double residual_avx2(
    const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt,
    std::span<const float> v4, std::span<const float> density_ratio, std::span<const float> factor,
    std::span<const float> k_total, std::span<float> k, float catch_up, float chebyshev) {
    return residual_pass(c, chunk, begin, end, dt, v4, density_ratio, factor, k_total, k, catch_up,
                         chebyshev);
}
[[gnu::flatten]] RIVULET_AVX2 void correct_avx2(const DfsphContext& c, std::size_t chunk, std::size_t begin,
                                                std::size_t end, std::span<const float> k,
                                                const DfsphVelocities& v) {
    correct_pass(c, chunk, begin, end, k, v);
}
[[gnu::flatten]] RIVULET_AVX2 DfsphPredictSums
predict_avx2(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt, float nu,
             float h, const float gravity[3], std::span<const float> v4, std::span<const float> k_warm,
             const DfsphDivergenceCheck& check, const DfsphVelocities& out) {
    return predict_pass<true>(c, chunk, begin, end, dt, nu, h, gravity, v4, k_warm, check, out);
}
#endif

}  // namespace

double dfsph_divergence_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                                 float dt, std::span<const float> v4, const DfsphDivergenceCheck& check,
                                 float chebyshev) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpu_has_avx2()) return divergence_residual_avx2(c, chunk, begin, end, dt, v4, check, chebyshev);
#endif
    return divergence_residual_pass(c, chunk, begin, end, dt, v4, check, chebyshev);
}

double dfsph_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt,
                      std::span<const float> v4, std::span<const float> density_ratio,
                      std::span<const float> factor, std::span<const float> k_total, std::span<float> k,
                      float catch_up, float chebyshev) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpu_has_avx2())
        return residual_avx2(c, chunk, begin, end, dt, v4, density_ratio, factor, k_total, k, catch_up,
                             chebyshev);
#endif
    return residual_pass(c, chunk, begin, end, dt, v4, density_ratio, factor, k_total, k, catch_up,
                         chebyshev);
}

void dfsph_correct(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                   std::span<const float> k, const DfsphVelocities& v) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpu_has_avx2()) return correct_avx2(c, chunk, begin, end, k, v);
#endif
    correct_pass(c, chunk, begin, end, k, v);
}

DfsphPredictSums dfsph_predict(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                               float dt, float nu, float h, const float gravity[3], std::span<const float> v4,
                               std::span<const float> k_warm, const DfsphDivergenceCheck& check,
                               const DfsphVelocities& out) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpu_has_avx2()) return predict_avx2(c, chunk, begin, end, dt, nu, h, gravity, v4, k_warm, check, out);
#endif
    return predict_pass<false>(c, chunk, begin, end, dt, nu, h, gravity, v4, k_warm, check, out);
}

}  // namespace rivulet
