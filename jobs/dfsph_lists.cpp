#include "jobs/dfsph_lists.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/simd4.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
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

#if defined(__x86_64__) && defined(__GNUC__)
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

// Appends those of eight candidates from sorted particle j on (offsets d from the particle, lanes past
// `valid` ignored) within h to cand / cand_r2 at `count`, in order: one permute compacts them.
RIVULET_AVX2 inline void append_near_avx2(__m256 dx, __m256 dy, __m256 dz, __m256 h2, unsigned valid,
                                          std::uint32_t j, std::uint32_t* cand, float* cand_r2, int& count) {
    const __m256 r2 =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)), _mm256_mul_ps(dz, dz));
    const unsigned hits =
        static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(r2, h2, _CMP_LT_OQ))) & valid;
    const __m256i order =
        _mm256_and_si256(_mm256_srlv_epi32(_mm256_set1_epi32(static_cast<int>(kCompactLanes[hits])),
                                           _mm256_setr_epi32(0, 4, 8, 12, 16, 20, 24, 28)),
                         _mm256_set1_epi32(7));
    _mm256_storeu_ps(cand_r2 + count, _mm256_permutevar8x32_ps(r2, order));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(cand + count),
                        _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(j)), order));
    count += std::popcount(hits);
}

// Appends the candidates of sorted particles [j, end) within h (r2 < h2) to cand / cand_r2 from
// `count` on, eight at a time, in order, with the baseline's bits (r2 = dx dx + dy dy + dz dz, no FMA);
// the row's last few by a masked load. `flush` empties the batch before it could overflow.
template <class Flush>
RIVULET_AVX2 inline void gather_row_avx2(const SphNeighbourhood& nb, float xi, float yi, float zi, float h2,
                                         std::uint32_t j, std::uint32_t end, std::uint32_t* cand,
                                         float* cand_r2, int& count, int batch, Flush& flush) {
    const __m256 qx = _mm256_set1_ps(xi), qy = _mm256_set1_ps(yi), qz = _mm256_set1_ps(zi);
    const __m256 reach = _mm256_set1_ps(h2);
    for (; j + 8 <= end; j += 8) {
        append_near_avx2(_mm256_sub_ps(qx, _mm256_loadu_ps(&nb.x[j])),
                         _mm256_sub_ps(qy, _mm256_loadu_ps(&nb.y[j])),
                         _mm256_sub_ps(qz, _mm256_loadu_ps(&nb.z[j])), reach, 0xffu, j, cand, cand_r2, count);
        if (count > batch - 8) flush();
    }
    if (j < end) {
        const unsigned left = end - j;
        const __m256i in_row = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(left)),
                                                  _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
        append_near_avx2(_mm256_sub_ps(qx, _mm256_maskload_ps(&nb.x[j], in_row)),
                         _mm256_sub_ps(qy, _mm256_maskload_ps(&nb.y[j], in_row)),
                         _mm256_sub_ps(qz, _mm256_maskload_ps(&nb.z[j], in_row)), reach, (1u << left) - 1u, j,
                         cand, cand_r2, count);
        if (count > batch - 8) flush();
    }
}
#endif

template <bool kAvx2>
RIVULET_INLINE void build_lists(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                                const SphWalls& walls, const DfsphWallTable& wall_table,
                                float full_neighbours, std::size_t begin, std::size_t end,
                                DfsphChunkLists& lists, const DfsphParticleOut& out) {
    std::size_t used = 0;  // pairs written; the vector's size is its high-water mark
    const float h2 = kernel.h2, h = kernel.h;
    // Candidates within h, gathered branch-free from each row of cells (every lane is written, the count
    // advances by the hits), their kernel values four at a time, then the sums and pairs in candidate
    // order; the order (and so every sum's bits) is the cell search's.
    constexpr int kBatch = 64;
    const simd::F4 h2_4 = simd::splat(h2), tiny_4 = simd::splat(1e-9f * h), h_4 = simd::splat(h);
    alignas(32) std::uint32_t cand[kBatch + 8];
    alignas(32) float cand_r2[kBatch + 8], cand_w[kBatch + 8], cand_f[kBatch + 8];
    for (std::size_t i = begin; i < end; ++i) {
        const float xi = nb.x[i], yi = nb.y[i], zi = nb.z[i];
        out.pair_begin[i] = static_cast<std::uint32_t>(used);
        float w_sum = 0.0f;
        float gx = 0.0f, gy = 0.0f, gz = 0.0f, g2 = 0.0f;
        int count = 0;
        const auto flush = [&] {
            for (int c = count; c % 4 != 0; ++c) cand_r2[c] = 0.0f;  // lanes past the candidates
            for (int c = 0; c < count; c += 4) {
                const simd::F4 r = simd::sqrt(simd::load(&cand_r2[c]));
                simd::F4 w, dwdq;
                kernel.at(r, w, dwdq);
                simd::store(&cand_w[c], w);
                // volume * (r <= 1e-9 h ? 0 : dwdq / (h r)), as the scalar form
                const simd::F4 g = simd::select_le(r, tiny_4, simd::splat(0.0f), dwdq / (h_4 * r));
                simd::store(&cand_f[c], simd::splat(volume) * g);
            }
            // Room for the batch (the vector only grows: in steady state nothing is allocated).
            if (lists.pairs.size() < used + std::size_t(count))
                lists.pairs.resize(
                    std::max({used + std::size_t(count), 2 * lists.pairs.size(), lists.pairs.capacity()}));
            DfsphPair* const pairs = lists.pairs.data();
            for (int c = 0; c < count; ++c) {
                const std::uint32_t j = cand[c];
                w_sum += cand_w[c];
                if (j == i) continue;
                const float f = cand_f[c], r2 = cand_r2[c];
                const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
                const DfsphPair pair{f * dx, f * dy, f * dz, j};
                pairs[used++] = pair;
                gx += pair.gx, gy += pair.gy, gz += pair.gz;
                g2 += f * f * r2;
            }
            count = 0;
        };
        sph_for_each_near_row(nb.grid, nb.cell_start, nb.key[i],
                              [&](std::uint32_t row_begin, std::uint32_t row_end) {
#if defined(__x86_64__) && defined(__GNUC__)
                                  if constexpr (kAvx2) {
                                      gather_row_avx2(nb, xi, yi, zi, h2, row_begin, row_end, cand, cand_r2,
                                                      count, kBatch, flush);
                                      return;
                                  }
#endif
                                  std::uint32_t j = row_begin;
                                  // Four candidates at a time (jobs/simd4.h: the same bits as the scalar loop
                                  // below).
                                  for (; j + 4 <= row_end; j += 4) {
                                      const simd::F4 dx = simd::splat(xi) - simd::load(&nb.x[j]);
                                      const simd::F4 dy = simd::splat(yi) - simd::load(&nb.y[j]);
                                      const simd::F4 dz = simd::splat(zi) - simd::load(&nb.z[j]);
                                      const simd::F4 r2 = dx * dx + dy * dy + dz * dz;
                                      const unsigned hits = simd::less_mask(r2, h2_4);
                                      alignas(16) float lanes[4];
                                      simd::store(lanes, r2);
                                      for (unsigned lane = 0; lane < 4; ++lane) {
                                          cand[count] = j + lane;
                                          cand_r2[count] = lanes[lane];
                                          count += int(hits >> lane & 1u);
                                      }
                                      if (count > kBatch - 8) flush();
                                  }
                                  for (; j < row_end; ++j) {
                                      const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
                                      const float r2 = dx * dx + dy * dy + dz * dz;
                                      cand[count] = j;
                                      cand_r2[count] = r2;
                                      count += int(r2 < h2);
                                      if (count > kBatch - 8) flush();
                                  }
                              });
        flush();
        out.pair_end[i] = static_cast<std::uint32_t>(used);
        // The walls: per face within h, B(s) and grad B = -A(s) n with n the face's inward normal. Faces
        // meeting at an edge or corner combine as if the kernel were separable: the fluid's side keeps
        // prod (1 - B_f) of the kernel's mass, so the edge's overlap is not counted twice.
        float wall = 0.0f;
        float b[3] = {0.0f, 0.0f, 0.0f};
        if (walls.enabled) {
            const float q[3] = {xi, yi, zi};
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
