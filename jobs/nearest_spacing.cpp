#include "jobs/nearest_spacing.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace rivulet {
namespace {

struct CellHash {
    float ox, oy, oz, inv;
    std::uint32_t mask;
    std::int32_t cell(float v, float o) const { return static_cast<std::int32_t>(std::floor((v - o) * inv)); }
    static std::uint32_t key(std::int32_t i, std::int32_t j, std::int32_t k, std::uint32_t mask) {
        return (std::uint32_t(i) * 73856093u ^ std::uint32_t(j) * 19349663u ^ std::uint32_t(k) * 83492791u) &
               mask;
    }
    std::uint32_t of(float x, float y, float z) const {
        return key(cell(x, ox), cell(y, oy), cell(z, oz), mask);
    }
};

// Entries one sample may test: more in its 27 cells means the spacing is below cell / 16, far under
// anything the caller tells apart, and scanning on would make a pile of coincident particles quadratic.
constexpr std::uint32_t kMaxScan = 4096;

}  // namespace

std::size_t nearest_spacing_table(std::size_t particles) {
    return std::bit_ceil(std::max<std::size_t>(64, 2 * particles));
}

float nearest_spacing(ConstPositions p, const float origin[3], float cell, std::uint32_t samples,
                      SpacingWorkspace ws) {
    const std::size_t n = p.size(), table = nearest_spacing_table(n);
    const CellHash h{origin[0], origin[1], origin[2], 1.0f / cell, static_cast<std::uint32_t>(table - 1)};
    std::fill(ws.heads.begin(), ws.heads.begin() + std::ptrdiff_t(table) + 1, 0u);
    for (std::size_t i = 0; i < n; ++i) ++ws.heads[h.of(p.x[i], p.y[i], p.z[i]) + 1];
    for (std::size_t b = 0; b < table; ++b) ws.heads[b + 1] += ws.heads[b];
    // Scatter with the heads as cursors, then shift them back: bucket b is [heads[b], heads[b + 1]).
    for (std::size_t i = 0; i < n; ++i) ws.order[ws.heads[h.of(p.x[i], p.y[i], p.z[i])]++] = std::uint32_t(i);
    for (std::size_t b = table; b > 0; --b) ws.heads[b] = ws.heads[b - 1];
    ws.heads[0] = 0;

    const std::size_t s_count = std::min<std::size_t>(samples, n);
    const float cap2 = cell * cell;
    for (std::size_t s = 0; s < s_count; ++s) {
        const std::size_t i = s * n / s_count;
        const float x = p.x[i], y = p.y[i], z = p.z[i];
        const std::int32_t ci = h.cell(x, h.ox), cj = h.cell(y, h.oy), ck = h.cell(z, h.oz);
        float best = cap2;
        std::uint32_t budget = kMaxScan;
        for (std::int32_t dk = -1; dk <= 1; ++dk)
            for (std::int32_t dj = -1; dj <= 1; ++dj)
                for (std::int32_t di = -1; di <= 1; ++di) {
                    const std::uint32_t b = CellHash::key(ci + di, cj + dj, ck + dk, h.mask);
                    const std::uint32_t end = std::min(ws.heads[b + 1], ws.heads[b] + budget);
                    budget -= end - ws.heads[b];
                    for (std::uint32_t e = ws.heads[b]; e < end; ++e) {
                        const std::uint32_t j = ws.order[e];
                        if (j == i) continue;
                        const float dx = p.x[j] - x, dy = p.y[j] - y, dz = p.z[j] - z;
                        best = std::min(best, dx * dx + dy * dy + dz * dz);
                    }
                }
        ws.nearest[s] = std::sqrt(best);
    }
    const auto mid = ws.nearest.begin() + std::ptrdiff_t(s_count / 2);
    std::nth_element(ws.nearest.begin(), mid, ws.nearest.begin() + std::ptrdiff_t(s_count));
    return *mid;
}

}  // namespace rivulet
