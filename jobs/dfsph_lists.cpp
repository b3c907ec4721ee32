#include "jobs/dfsph_lists.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/simd4.h"
#include "jobs/vector_lanes.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <numbers>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace rivulet {

DfsphWallTable::DfsphWallTable(const SphCubicKernel& kernel, float volume, float d) : h(kernel.h) {
    const int reach = static_cast<int>(std::ceil(kernel.h / d));
    for (int k = 0; k <= kSamples; ++k) {
        const double s = double(h) * k / kSamples;
        double sum = 0;
        for (int row = 0; 2.0 * s + row * double(d) < double(h); ++row) {
            const double depth = 2.0 * s + row * double(d);
            for (int z = -reach; z <= reach; ++z)
                for (int x = -reach; x <= reach; ++x) {
                    const double r2 = (double(x) * x + double(z) * z) * double(d) * d + depth * depth;
                    sum += kernel.w(static_cast<float>(r2));
                }
        }
        mass[k] = static_cast<float>(double(volume) * sum);
    }
}

void DfsphWallTable::at(float s, float& b, float& a) const {
    if (s >= h) {
        b = a = 0.0f;
        return;
    }
    const float t = (s > 0.0f ? s : 0.0f) / h * kSamples;
    int k = static_cast<int>(t);
    if (k >= kSamples) k = kSamples - 1;
    const float u = t - static_cast<float>(k);
    b = mass[k] + (mass[k + 1] - mass[k]) * u;
    // The slope of the interpolant itself, so that the solver's predicted change of B is exact to first
    // order: DFSPH turns any mismatch between predicted and realized density into velocity / dt.
    a = (mass[k] - mass[k + 1]) * (static_cast<float>(kSamples) / h);
}

namespace {

using f4 = VectorLanes<4>::f;
using f8 = VectorLanes<8>::f;
using i8 = VectorLanes<8>::i;

// A batch of candidates within h of particle i, compacted in cell-search order: index, squared
// distance, offset x_i - x_j.
struct Candidates {
    static constexpr int kBatch = 64;  // flushed from kBatch - 8 on: room for a gather of eight
    alignas(32) std::uint32_t j[kBatch + 8];
    alignas(32) float r2[kBatch + 8], dx[kBatch + 8], dy[kBatch + 8], dz[kBatch + 8];
    int count = 0;
};

// The gathers keep the batch's count in a register (c.j's stores may alias an int, so a count in memory
// is reloaded after each); past kBatch - 8 the batch is flushed (whole groups of eight: fewer than eight
// stay), so the next gather of eight fits. Returns the count after.
template <class Flush>
RIVULET_INLINE int flush_if_full(Candidates& c, int count, Flush& flush) {
    if (count <= Candidates::kBatch - 8) return count;
    c.count = count;
    flush();
    return c.count;
}

#if defined(__x86_64__) && defined(__GNUC__)
// The scan's flush of a full batch, out of line: a particle needs it only past kBatch - 8 hits, and
// inlined into the scan loop its registers spilled the loop's base pointers and index vector to the
// stack in every group of eight (the build was 7-10 % slower).
template <class Flush>
[[gnu::noinline, gnu::cold]] RIVULET_AVX2 void flush_cold_avx2(Flush& flush) {
    flush();
}
template <class Flush>
RIVULET_INLINE int flush_if_full_avx2(Candidates& c, int count, Flush& flush) {
    if (count <= Candidates::kBatch - 8) [[likely]]
        return count;
    c.count = count;
    flush_cold_avx2(flush);
    return c.count;
}

// Per 8-bit hit mask, the indices of its set lanes in order, four bits each: the compaction of eight
// candidates is then one permute.
constexpr std::array<std::uint32_t, 256> kCompactLanes = [] {
    std::array<std::uint32_t, 256> table{};
    for (unsigned mask = 0; mask < 256; ++mask) {
        unsigned k = 0;
        for (unsigned lane = 0; lane < 8; ++lane)
            if (mask >> lane & 1u) table[mask] |= lane << (4 * k++);
    }
    return table;
}();

// The permute that moves the set lanes of an 8-bit hit mask to the front, in order (kCompactLanes).
RIVULET_AVX2 inline __m256i compact_order_avx2(unsigned hits) {
    return _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(kCompactLanes[hits])),
                                              _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                            _mm256_set1_epi32(7));
}

// Appends those of eight candidates (offsets d from particle `self`, indices `index`, lanes past
// `valid` ignored) within h, itself excluded, to the batch after its first `count`, in order: one permute
// per column compacts them. Returns the new count.
RIVULET_AVX2 inline int append_near_avx2(__m256 dx, __m256 dy, __m256 dz, __m256i index, __m256 h2,
                                         unsigned valid, std::uint32_t self, Candidates& c, int count) {
    const __m256 r2 =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const unsigned itself = static_cast<unsigned>(_mm256_movemask_ps(
        _mm256_castsi256_ps(_mm256_cmpeq_epi32(index, _mm256_set1_epi32(static_cast<int>(self))))));
    const unsigned hits =
        static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(r2, h2, _CMP_LT_OQ))) & valid & ~itself;
    const __m256i order = compact_order_avx2(hits);
    _mm256_storeu_ps(c.r2 + count, _mm256_permutevar8x32_ps(r2, order));
    _mm256_storeu_ps(c.dx + count, _mm256_permutevar8x32_ps(dx, order));
    _mm256_storeu_ps(c.dy + count, _mm256_permutevar8x32_ps(dy, order));
    _mm256_storeu_ps(c.dz + count, _mm256_permutevar8x32_ps(dz, order));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(c.j + count), _mm256_permutevar8x32_epi32(index, order));
    return count + std::popcount(hits);
}

// Appends the candidates among the near cells' particles within h of particle `self` at q (r2 < h2,
// r2 = dx dx + dy dy + dz dz without FMA, as the baseline), eight at a time; the last few by a masked
// load. `flush` empties the batch before it could overflow.
template <class Flush>
RIVULET_AVX2 inline void gather_near_avx2(const DfsphNearCells& near, std::size_t n, const float q[3],
                                          std::uint32_t self, float h2, Candidates& c, Flush& flush) {
    const __m256 qx = _mm256_set1_ps(q[0]), qy = _mm256_set1_ps(q[1]), qz = _mm256_set1_ps(q[2]);
    const __m256 reach = _mm256_set1_ps(h2);
    const float *x = near.x.data(), *y = near.y.data(), *z = near.z.data();
    const std::uint32_t* index = near.j.data();
    int count = c.count;
    std::size_t k = 0;
    for (; k + 8 <= n; k += 8) {
        count = append_near_avx2(
            _mm256_sub_ps(qx, _mm256_loadu_ps(x + k)), _mm256_sub_ps(qy, _mm256_loadu_ps(y + k)),
            _mm256_sub_ps(qz, _mm256_loadu_ps(z + k)),
            _mm256_loadu_si256(reinterpret_cast<const __m256i*>(index + k)), reach, 0xffu, self, c, count);
        count = flush_if_full_avx2(c, count, flush);
    }
    if (k < n) {
        const auto left = static_cast<unsigned>(n - k);
        const __m256i in = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(left)),
                                              _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        count = append_near_avx2(_mm256_sub_ps(qx, _mm256_maskload_ps(x + k, in)),
                                 _mm256_sub_ps(qy, _mm256_maskload_ps(y + k, in)),
                                 _mm256_sub_ps(qz, _mm256_maskload_ps(z + k, in)),
                                 _mm256_maskload_epi32(reinterpret_cast<const int*>(index + k), in), reach,
                                 (1u << left) - 1u, self, c, count);
        count = flush_if_full_avx2(c, count, flush);
    }
    c.count = count;
}
#endif

// The baseline's gather of the same candidates: four at a time, every lane written and the count
// advanced by its hit.
template <class Flush>
RIVULET_INLINE void gather_near(const DfsphNearCells& near, std::size_t n, const float q[3],
                                std::uint32_t self, float h2, Candidates& c, Flush& flush) {
    const simd::F4 qx = simd::splat(q[0]), qy = simd::splat(q[1]), qz = simd::splat(q[2]);
    const simd::F4 reach = simd::splat(h2);
    int count = c.count;
    std::size_t k = 0;
    for (; k + 4 <= n; k += 4) {
        const simd::F4 dx = qx - simd::load(&near.x[k]), dy = qy - simd::load(&near.y[k]),
                       dz = qz - simd::load(&near.z[k]);
        const simd::F4 r2 = dx * dx + dy * dy + dz * dz;
        const unsigned hits = simd::less_mask(r2, reach);
        alignas(16) float lr2[4], ldx[4], ldy[4], ldz[4];
        simd::store(lr2, r2), simd::store(ldx, dx), simd::store(ldy, dy), simd::store(ldz, dz);
        for (unsigned lane = 0; lane < 4; ++lane) {
            const int m = count;
            const std::uint32_t j = near.j[k + lane];
            c.j[m] = j, c.r2[m] = lr2[lane], c.dx[m] = ldx[lane], c.dy[m] = ldy[lane], c.dz[m] = ldz[lane];
            count += int((hits >> lane & 1u) & unsigned(j != self));
        }
        count = flush_if_full(c, count, flush);
    }
    for (; k < n; ++k) {
        const float dx = q[0] - near.x[k], dy = q[1] - near.y[k], dz = q[2] - near.z[k];
        const float r2 = dx * dx + dy * dy + dz * dz;
        const int m = count;
        const std::uint32_t j = near.j[k];
        c.j[m] = j, c.r2[m] = r2, c.dx[m] = dx, c.dy[m] = dy, c.dz[m] = dz;
        count += int(r2 < h2 && j != self);
        count = flush_if_full(c, count, flush);
    }
    c.count = count;
}

// The box around one cell's particles (their tight bounds, not the cell's): a candidate whose distance
// to it is h or more is no particle's neighbour there. Rounding is monotonic, so each particle's own
// test, fl((q - x)^2 ...) < h^2, fails wherever this one, fl(e^2 ...) with e the distance per axis to the
// box, does: culling changes no list.
struct CellBox {
    float lo[3], hi[3];
};

CellBox cell_box(const SphNeighbourhood& nb, std::uint32_t key) {
    CellBox box{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
    const std::span<const float> axes[3] = {nb.x, nb.y, nb.z};
    for (std::uint32_t k = nb.cell_start[key]; k < nb.cell_start[key + 1]; ++k)
        for (int a = 0; a < 3; ++a) {  // a NaN position is left out: it has no neighbours anyway
            const float v = axes[a][k];
            box.lo[a] = v < box.lo[a] ? v : box.lo[a];
            box.hi[a] = v > box.hi[a] ? v : box.hi[a];
        }
    return box;
}

// Whether candidate (x, y, z) lies within h of the box. A NaN coordinate reads as no gap, so the
// candidate is kept and left to each particle's own test, which no NaN passes.
RIVULET_INLINE bool near_box(const CellBox& b, float x, float y, float z, float h2) {
    const auto gap = [](float lo, float hi, float v) {
        const float below = lo - v, above = v - hi;
        const float e = below > above ? below : above;
        return e > 0.0f ? e : 0.0f;
    };
    const float ex = gap(b.lo[0], b.hi[0], x), ey = gap(b.lo[1], b.hi[1], y), ez = gap(b.lo[2], b.hi[2], z);
    return ex * ex + ey * ey + ez * ez < h2;
}

#if defined(__x86_64__) && defined(__GNUC__)
// Appends the particles [begin, end) of the sorted arrays that lie within h of the box to the run after
// its first `count`, eight at a time with a permute as append_near_avx2; returns the new count.
RIVULET_AVX2 inline std::size_t append_near_box_avx2(const SphNeighbourhood& nb, const CellBox& b,
                                                     std::uint32_t begin, std::uint32_t end, float h2,
                                                     DfsphNearCells& near, std::size_t count) {
    const __m256 zero = _mm256_setzero_ps(), reach = _mm256_set1_ps(h2);
    const float* const axis[3] = {nb.x.data(), nb.y.data(), nb.z.data()};
    float* const out[3] = {near.x.data(), near.y.data(), near.z.data()};
    std::uint32_t* const out_j = near.j.data();
    for (std::uint32_t k = begin; k < end; k += 8) {
        const unsigned left = end - k;
        const __m256i in = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(left < 8 ? left : 8)),
                                              _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        __m256 v[3], d2 = zero;
        for (int a = 0; a < 3; ++a) {
            v[a] = _mm256_maskload_ps(axis[a] + k, in);
            const __m256 below = _mm256_sub_ps(_mm256_set1_ps(b.lo[a]), v[a]);
            const __m256 above = _mm256_sub_ps(v[a], _mm256_set1_ps(b.hi[a]));
            // As near_box: the larger gap (maxps gives the second operand where one is NaN), then >= 0.
            const __m256 e = _mm256_max_ps(above, below);
            const __m256 g = _mm256_and_ps(e, _mm256_cmp_ps(e, zero, _CMP_GT_OQ));
            d2 = a == 0 ? _mm256_mul_ps(g, g) : _mm256_add_ps(d2, _mm256_mul_ps(g, g));
        }
        const unsigned hits =
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d2, reach, _CMP_LT_OQ))) &
            static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(in)));
        const __m256i order = compact_order_avx2(hits);
        for (int a = 0; a < 3; ++a) _mm256_storeu_ps(out[a] + count, _mm256_permutevar8x32_ps(v[a], order));
        const __m256i j = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(k)),
                                           _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out_j + count), _mm256_permutevar8x32_epi32(j, order));
        count += static_cast<std::size_t>(std::popcount(hits));
    }
    return count;
}
#endif

// The particles of the 27 cells around cell `key` that lie within h of its particles' box, rows in
// sph_for_each_near_row's order, copied into one run (every particle of that cell then scans the same
// run); returns their number. The box culls about two fifths of the 27 cells' particles.
template <bool kAvx2>
RIVULET_INLINE std::size_t gather_cells(const SphNeighbourhood& nb, std::uint32_t key, float h2,
                                        DfsphNearCells& near) {
    std::size_t n = 0;
    sph_for_each_near_row(nb.grid, nb.cell_start, key, [&](std::uint32_t b, std::uint32_t e) { n += e - b; });
    if (near.x.size() < n + 8) {  // eight past the end: the AVX2 build writes whole groups
        const std::size_t size = std::max(n + 8, 2 * near.x.size());
        near.x.resize(size), near.y.resize(size), near.z.resize(size), near.j.resize(size);
    }
    const CellBox box = cell_box(nb, key);
    std::size_t k = 0;
    sph_for_each_near_row(nb.grid, nb.cell_start, key, [&](std::uint32_t b, std::uint32_t e) {
#if defined(__x86_64__) && defined(__GNUC__)
        if constexpr (kAvx2) {
            k = append_near_box_avx2(nb, box, b, e, h2, near, k);
            return;
        }
#endif
        for (std::uint32_t m = b; m < e; ++m) {  // every candidate written, the count advanced by its hit
            const float x = nb.x[m], y = nb.y[m], z = nb.z[m];
            near.x[k] = x, near.y[k] = y, near.z[k] = z, near.j[k] = m;
            k += near_box(box, x, y, z, h2) ? 1 : 0;
        }
    });
    return k;
}

// Helpers on eight lanes take and give them by reference: no 32-byte vector crosses a function boundary
// of the baseline build.
RIVULET_INLINE void load8(const float* p, f8& v) {
    std::memcpy(&v, p, sizeof v);
}
// out = m ? a : b per lane (m all ones or all zeros).
RIVULET_INLINE void select8(const i8& m, const f8& a, const f8& b, f8& out) {
    out = reinterpret_cast<f8>((m & reinterpret_cast<i8>(a)) | (~m & reinterpret_cast<i8>(b)));
}
// The eight lanes' sum in a fixed tree: (l0 + l4) + (l1 + l5) ... as pairs, then pairs of pairs.
RIVULET_INLINE float sum8(const f8& a) {
    const f4 s = __builtin_shufflevector(a, a, 0, 1, 2, 3) + __builtin_shufflevector(a, a, 4, 5, 6, 7);
    return (s[0] + s[1]) + (s[2] + s[3]);
}

// Eight pairs from their columns (radial factors, indices), interleaved: two shuffles, two stores.
RIVULET_INLINE void store_pairs8(const f8& f, const std::uint32_t* j, DfsphPair* out) {
    i8 ji;
    std::memcpy(&ji, j, sizeof ji);
    const f8 jf = reinterpret_cast<f8>(ji);
    const f8 lo = __builtin_shufflevector(f, jf, 0, 8, 1, 9, 2, 10, 3, 11);
    const f8 hi = __builtin_shufflevector(f, jf, 4, 12, 5, 13, 6, 14, 7, 15);
    std::memcpy(out, &lo, sizeof lo), std::memcpy(out + 4, &hi, sizeof hi);
}

// The lane sums of one particle's pairs: sum W, sum V grad W (per axis), sum |V grad W|^2.
struct PairSums {
    f8 w, gx, gy, gz, g2;
    f8 cx, cy, cz;  // sum (k_i + k_j) V grad W_ij, where a warm start is applied
    // Member by member from a zero register: the aggregate's zero-initialization became `rep stos`,
    // whose start-up cost every particle paid (3.6 % of the build on AMD's Zen 3).
    RIVULET_INLINE void clear() {
        const f8 zero{};
        w = zero, gx = zero, gy = zero, gz = zero, g2 = zero, cx = zero, cy = zero, cz = zero;
    }
};

// Kernel values, V grad W_ij and the pairs of a batch, eight candidates at a time; each lane sums its
// candidates (lanes past the batch add nothing), so a particle's sums depend only on its candidates'
// order, never on the build or the thread.
RIVULET_INLINE void flush_batch(const SphCubicKernel& kernel, float volume, Candidates& c, PairSums& sums,
                                DfsphPair* pairs, const float* k_warm, float ki, std::uint32_t self) {
    const i8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
    const float tiny = 1e-9f * kernel.h;
    // Lanes past the batch read zeros (whatever they held could be an infinity, and 0 inf is NaN) and
    // index the particle itself: they are stored as its list's pad pairs (0, i), whose terms in the passes
    // read only its own values.
    for (int k = c.count; k % 8 != 0; ++k) c.r2[k] = c.dx[k] = c.dy[k] = c.dz[k] = 0.0f, c.j[k] = self;
    for (int k = 0; k < c.count; k += 8) {
        const i8 valid = lane < (c.count - k);
        f8 r2, r, dx, dy, dz;
        load8(c.r2 + k, r2), lane_sqrt(r2, r);
        load8(c.dx + k, dx), load8(c.dy + k, dy), load8(c.dz + k, dz);
        f8 w, dwdq, f;
        kernel.at(r, w, dwdq);
        select8(valid & (r > tiny), volume * (dwdq / (kernel.h * r)), f8{}, f);
        select8(valid, w, f8{}, w);
        const f8 gx = f * dx, gy = f * dy, gz = f * dz;
        sums.w += w;
        sums.gx += gx, sums.gy += gy, sums.gz += gz;
        sums.g2 += f * f * r2;
        if (k_warm != nullptr) {
            const std::uint32_t* j = c.j + k;  // lanes past the batch index the particle; their f is 0
            const f8 kj = {k_warm[j[0]], k_warm[j[1]], k_warm[j[2]], k_warm[j[3]],
                           k_warm[j[4]], k_warm[j[5]], k_warm[j[6]], k_warm[j[7]]};
            const f8 kij = ki + kj;
            sums.cx += kij * gx, sums.cy += kij * gy, sums.cz += kij * gz;
        }
        store_pairs8(f, c.j + k, pairs + k);
    }
}

template <bool kAvx2>
RIVULET_INLINE void build_lists(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                                const SphWalls& walls, const DfsphWallTable& wall_table,
                                float full_neighbours, std::size_t begin, std::size_t end,
                                DfsphChunkLists& lists, const DfsphParticleOut& out) {
    std::size_t used = 0;  // pairs written; the vector's size is its high-water mark
    const float h2 = kernel.h2;
    Candidates batch;
    const float* const k_warm = out.k_warm.empty() ? nullptr : out.k_warm.data();
    std::uint32_t key = 0;
    std::size_t near = 0;  // particles in the cells around `key`, in lists.near
    for (std::size_t i = begin; i < end; ++i) {
        const float q[3] = {nb.x[i], nb.y[i], nb.z[i]};
        const auto self = static_cast<std::uint32_t>(i);
        out.pair_begin[i] = static_cast<std::uint32_t>(used);
        PairSums sums;
        sums.clear();
        const float ki = k_warm != nullptr ? k_warm[i] : 0.0f;
        batch.count = 0;
        const auto flush = [&] {
            // Whole groups of eight are written; the lanes past the batch are overwritten or stale.
            const std::size_t room = used + std::size_t(batch.count) + 8;
            if (lists.pairs.size() < room)
                lists.pairs.resize(std::max({room, 2 * lists.pairs.size(), lists.pairs.capacity()}));
            flush_batch(kernel, volume, batch, sums, lists.pairs.data() + used, k_warm, ki, self);
            used += std::size_t(batch.count);
            batch.count = 0;
        };
        // A full batch within the particle's candidates: its whole groups of eight, the rest kept for
        // the next. Each candidate then sums in lane (its place among the particle's hits) mod 8, however
        // often and wherever a gather flushes (after four candidates in the baseline, eight in AVX2): the
        // whole batch padded to eight gave the two builds different sums where a particle has more than
        // kBatch - 8 neighbours.
        const auto flush_groups = [&] {
            const int whole = batch.count & ~7, rest = batch.count - whole;
            batch.count = whole;
            flush();
            for (int k = 0; k < rest; ++k) {
                batch.r2[k] = batch.r2[whole + k], batch.dx[k] = batch.dx[whole + k];
                batch.dy[k] = batch.dy[whole + k], batch.dz[k] = batch.dz[whole + k];
                batch.j[k] = batch.j[whole + k];
            }
            batch.count = rest;
        };
        if (nb.key[i] != key || i == begin)
            key = nb.key[i], near = gather_cells<kAvx2>(nb, key, h2, lists.near);
#if defined(__x86_64__) && defined(__GNUC__)
        if constexpr (kAvx2)
            gather_near_avx2(lists.near, near, q, self, h2, batch, flush_groups);
        else
#endif
            gather_near(lists.near, near, q, self, h2, batch, flush_groups);
        flush();
        out.pair_end[i] = static_cast<std::uint32_t>(used);
        used = (used + 3) & ~std::size_t(3);  // the flush wrote the pad pairs (0, i) up to here
        out.x4[4 * i] = q[0], out.x4[4 * i + 1] = q[1], out.x4[4 * i + 2] = q[2], out.x4[4 * i + 3] = 0.0f;
        float gx = sum8(sums.gx), gy = sum8(sums.gy), gz = sum8(sums.gz);
        const float g2 = sum8(sums.g2);
        const float w_sum = kernel.k + sum8(sums.w);  // W(0) = k: the particle itself
        // The walls: per face within h, B(s) and grad B = -A(s) n with n the face's inward normal. Faces
        // meeting at an edge or corner combine as if the kernel were separable: the fluid's side keeps
        // prod (1 - B_f) of the kernel's mass, so the edge's overlap is not counted twice.
        float wall = 0.0f;
        float b[3] = {0.0f, 0.0f, 0.0f};
        if (walls.enabled) {
            float keep[6], grad[6];
            int faces = 0;
            int axis_of[6];
            for (int a = 0; a < 3; ++a) {
                float mass = 0.0f, slope = 0.0f;
                wall_table.at(q[a] - walls.min[a], mass, slope);
                if (mass > 0.0f) keep[faces] = 1.0f - mass, grad[faces] = -slope, axis_of[faces++] = a;
                wall_table.at(walls.max[a] - q[a], mass, slope);
                if (mass > 0.0f) keep[faces] = 1.0f - mass, grad[faces] = slope, axis_of[faces++] = a;
            }
            float inside = 1.0f;
            for (int f = 0; f < faces; ++f) inside *= keep[f];
            wall = 1.0f - inside;
            for (int f = 0; f < faces; ++f) {
                float others = 1.0f;
                for (int g = 0; g < faces; ++g)
                    if (g != f) others *= keep[g];
                b[axis_of[f]] += grad[f] * others;
            }
        }
        out.wall_gx[i] = b[0], out.wall_gy[i] = b[1], out.wall_gz[i] = b[2];
        gx += b[0], gy += b[1], gz += b[2];
        out.density_ratio[i] = volume * w_sum + wall;
        out.support[i] = static_cast<float>(out.pair_end[i] - out.pair_begin[i]) + wall * full_neighbours;
        const float d = gx * gx + gy * gy + gz * gz + g2;
        out.factor[i] = d > 1e-6f / kernel.h2 ? 1.0f / d : 0.0f;  // V grad W ~ 1 / h
        if (k_warm != nullptr) {  // v_i -= sum_j (k_i + k_j) V grad W_ij + k_i grad B_i
            const float vx = out.vx[i] - (sum8(sums.cx) + ki * b[0]);
            const float vy = out.vy[i] - (sum8(sums.cy) + ki * b[1]);
            const float vz = out.vz[i] - (sum8(sums.cz) + ki * b[2]);
            out.vx[i] = vx, out.vy[i] = vy, out.vz[i] = vz;
            out.v4[4 * i] = vx, out.v4[4 * i + 1] = vy, out.v4[4 * i + 2] = vz, out.v4[4 * i + 3] = 0.0f;
        }
    }
}

#if defined(__x86_64__) && defined(__GNUC__)
[[gnu::flatten]] RIVULET_AVX2 void build_lists_avx2(const SphNeighbourhood& nb, const SphCubicKernel& kernel,
                                                    float volume, const SphWalls& walls,
                                                    const DfsphWallTable& wall_table, float full_neighbours,
                                                    std::size_t begin, std::size_t end,
                                                    DfsphChunkLists& lists, const DfsphParticleOut& out) {
    build_lists<true>(nb, kernel, volume, walls, wall_table, full_neighbours, begin, end, lists, out);
}
#endif

}  // namespace

void dfsph_build_lists(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                       const SphWalls& walls, const DfsphWallTable& wall_table, float full_neighbours,
                       std::size_t begin, std::size_t end, DfsphChunkLists& lists,
                       const DfsphParticleOut& out) {
#if defined(__x86_64__) && defined(__GNUC__)
    if (cpu_has_avx2()) {
        build_lists_avx2(nb, kernel, volume, walls, wall_table, full_neighbours, begin, end, lists, out);
        return;
    }
#endif
    dfsph_build_lists_baseline(nb, kernel, volume, walls, wall_table, full_neighbours, begin, end, lists,
                               out);
}

void dfsph_build_lists_baseline(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                                const SphWalls& walls, const DfsphWallTable& wall_table,
                                float full_neighbours, std::size_t begin, std::size_t end,
                                DfsphChunkLists& lists, const DfsphParticleOut& out) {
    build_lists<false>(nb, kernel, volume, walls, wall_table, full_neighbours, begin, end, lists, out);
}

float dfsph_lattice_volume(const SphCubicKernel& kernel, float d) {
    const int reach = static_cast<int>(std::ceil(kernel.h / d));
    double sum = 0;
    for (int z = -reach; z <= reach; ++z)
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) {
                const double r2 = (double(x) * x + double(y) * y + double(z) * z) * double(d) * d;
                sum += kernel.w(static_cast<float>(r2));
            }
    return static_cast<float>(1.0 / sum);
}

int dfsph_lattice_neighbours(const SphCubicKernel& kernel, float d) {
    const int reach = static_cast<int>(std::ceil(kernel.h / d));
    int count = 0;
    for (int z = -reach; z <= reach; ++z)
        for (int y = -reach; y <= reach; ++y)
            for (int x = -reach; x <= reach; ++x) {
                const float r2 = float(x * x + y * y + z * z) * d * d;
                if (r2 > 0.0f && r2 < kernel.h2) ++count;
            }
    return count;
}

}  // namespace rivulet
