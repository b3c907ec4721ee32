#include "jobs/dfsph_lists.h"

#include "jobs/simd4.h"

#include <algorithm>
#include <cmath>
#include <numbers>

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

void dfsph_build_lists(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                       const SphWalls& walls, const DfsphWallTable& wall_table, float full_neighbours,
                       std::size_t begin, std::size_t end, DfsphChunkLists& lists,
                       const DfsphParticleOut& out) {
    lists.pairs.clear();
    const float h2 = kernel.h2, h = kernel.h;
    // Candidates within h, gathered branch-free from each row of cells (every lane is written, the count
    // advances by the hits), their kernel values four at a time, then the sums and pairs in candidate
    // order; the order (and so every sum's bits) is the cell search's.
    constexpr int kBatch = 64;
    const simd::F4 h2_4 = simd::splat(h2), tiny_4 = simd::splat(1e-9f * h), h_4 = simd::splat(h);
    alignas(16) std::uint32_t cand[kBatch + 4];
    alignas(16) float cand_r2[kBatch + 4], cand_w[kBatch + 4], cand_f[kBatch + 4];
    for (std::size_t i = begin; i < end; ++i) {
        const float xi = nb.x[i], yi = nb.y[i], zi = nb.z[i];
        out.pair_begin[i] = static_cast<std::uint32_t>(lists.pairs.size());
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
            for (int c = 0; c < count; ++c) {
                const std::uint32_t j = cand[c];
                w_sum += cand_w[c];
                if (j == i) continue;
                const float f = cand_f[c], r2 = cand_r2[c];
                const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
                const DfsphPair pair{f * dx, f * dy, f * dz, j};
                lists.pairs.push_back(pair);
                gx += pair.gx, gy += pair.gy, gz += pair.gz;
                g2 += f * f * r2;
            }
            count = 0;
        };
        sph_for_each_near_row(nb.grid, nb.cell_start, nb.key[i],
                              [&](std::uint32_t row_begin, std::uint32_t row_end) {
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
                                      if (count > kBatch - 4) flush();
                                  }
                                  for (; j < row_end; ++j) {
                                      const float dx = xi - nb.x[j], dy = yi - nb.y[j], dz = zi - nb.z[j];
                                      const float r2 = dx * dx + dy * dy + dz * dz;
                                      cand[count] = j;
                                      cand_r2[count] = r2;
                                      count += int(r2 < h2);
                                      if (count > kBatch - 4) flush();
                                  }
                              });
        flush();
        out.pair_end[i] = static_cast<std::uint32_t>(lists.pairs.size());
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
