#include "jobs/particle_spacing.h"

#include <algorithm>
#include <bit>
#include <cmath>

#include "jobs/sph_cubic_kernel.h"

namespace rivulet {
namespace {

// Entries one sample may test: more in its 27 cells means a pile far denser than the cell, and scanning
// on would make coincident particles quadratic.
constexpr std::uint32_t kMaxScan = 4096;

struct CellHash {
    float ox, oy, oz, inv;
    std::uint32_t mask;
    std::int32_t cell(float v, float o) const { return static_cast<std::int32_t>(std::floor((v - o) * inv)); }
    std::uint32_t key(std::int32_t i, std::int32_t j, std::int32_t k) const {
        return (std::uint32_t(i) * 73856093u ^ std::uint32_t(j) * 19349663u ^ std::uint32_t(k) * 83492791u) &
               mask;
    }
    std::uint32_t of(float x, float y, float z) const { return key(cell(x, ox), cell(y, oy), cell(z, oz)); }
};

// Buckets of `cell`-wide cells: bucket b holds order[heads[b] .. heads[b + 1]).
CellHash build(ConstPositions p, const float origin[3], float cell, SpacingWorkspace ws) {
    const std::size_t n = p.size(), table = spacing_table_size(n);
    const CellHash h{origin[0], origin[1], origin[2], 1.0f / cell, static_cast<std::uint32_t>(table - 1)};
    std::fill(ws.heads.begin(), ws.heads.begin() + std::ptrdiff_t(table) + 1, 0u);
    for (std::size_t i = 0; i < n; ++i) ++ws.heads[h.of(p.x[i], p.y[i], p.z[i]) + 1];
    for (std::size_t b = 0; b < table; ++b) ws.heads[b + 1] += ws.heads[b];
    // Scatter with the heads as cursors, then shift them back.
    for (std::size_t i = 0; i < n; ++i) ws.order[ws.heads[h.of(p.x[i], p.y[i], p.z[i])]++] = std::uint32_t(i);
    for (std::size_t b = table; b > 0; --b) ws.heads[b] = ws.heads[b - 1];
    ws.heads[0] = 0;
    return h;
}

// Calls visit(j, squared distance) for the particles in the buckets of the 27 cells around particle i (i
// included), at most kMaxScan of them. A bucket two of the cells share is visited once: it holds every
// particle of both, so a density sum counts nothing twice and misses nothing.
template <class Visit>
void for_each_near(ConstPositions p, const CellHash& h, const SpacingWorkspace& ws, std::size_t i,
                   Visit&& visit) {
    const float x = p.x[i], y = p.y[i], z = p.z[i];
    const std::int32_t ci = h.cell(x, h.ox), cj = h.cell(y, h.oy), ck = h.cell(z, h.oz);
    std::uint32_t seen[27], seen_n = 0, budget = kMaxScan;
    for (std::int32_t dk = -1; dk <= 1; ++dk)
        for (std::int32_t dj = -1; dj <= 1; ++dj)
            for (std::int32_t di = -1; di <= 1; ++di) {
                const std::uint32_t b = h.key(ci + di, cj + dj, ck + dk);
                if (std::find(seen, seen + seen_n, b) != seen + seen_n) continue;  // a shared bucket
                seen[seen_n++] = b;
                const std::uint32_t end = std::min(ws.heads[b + 1], ws.heads[b] + budget);
                budget -= end - ws.heads[b];
                for (std::uint32_t e = ws.heads[b]; e < end; ++e) {
                    const std::uint32_t j = ws.order[e];
                    const float dx = p.x[j] - x, dy = p.y[j] - y, dz = p.z[j] - z;
                    visit(j, dx * dx + dy * dy + dz * dz);
                }
            }
}

float quantile(std::span<float> v, std::size_t count, double q) {
    const auto at = v.begin() + std::ptrdiff_t(std::min(count - 1, std::size_t(q * double(count))));
    std::nth_element(v.begin(), at, v.begin() + std::ptrdiff_t(count));
    return *at;
}

}  // namespace

std::size_t spacing_table_size(std::size_t particles) {
    return std::bit_ceil(std::max<std::size_t>(64, 2 * particles));
}

float particle_spacing(ConstPositions p, const float origin[3], float cap, std::uint32_t samples,
                       SpacingWorkspace ws) {
    const std::size_t n = p.size(), s_count = std::min<std::size_t>(samples, n);
    auto sample = [&](std::size_t s) { return s * n / s_count; };

    CellHash h = build(p, origin, cap, ws);
    for (std::size_t s = 0; s < s_count; ++s) {
        const std::size_t i = sample(s);
        float best = cap * cap;
        for_each_near(p, h, ws, i, [&](std::uint32_t j, float r2) {
            if (j != i) best = std::min(best, r2);
        });
        ws.values[s] = std::sqrt(best);
    }
    const float d0 = quantile(ws.values, s_count, 0.5);
    if (!(d0 < cap)) return cap;
    // Ten times denser than the cap is denser than any caller tells apart (the slices field clamps at an
    // eighth); stopping here also keeps the second pass's cells at least a quarter of the cap.
    if (!(d0 >= 0.1f * cap)) return d0;

    const float support = 3.0f * d0;
    const SphCubicKernel w(support);
    h = build(p, origin, support, ws);
    for (std::size_t s = 0; s < s_count; ++s) {
        double density = 0;
        for_each_near(p, h, ws, sample(s), [&](std::uint32_t, float r2) { density += double(w.w(r2)); });
        ws.values[s] = static_cast<float>(density);
    }
    const float dense = quantile(ws.values, s_count, 0.8);
    return std::min(cap, static_cast<float>(std::cbrt(1.0 / double(dense))));
}

}  // namespace rivulet
