#include "jobs/particle_spacing.h"

#include <algorithm>
#include <cmath>

#include "jobs/cell_hash.h"
#include "jobs/sph_cubic_kernel.h"

namespace rivulet {
namespace {

// Entries one sample may test: more in its 27 cells means a pile far denser than the cell, and scanning
// on would make coincident particles quadratic.
constexpr std::uint32_t kMaxScan = 4096;

float quantile(std::span<float> v, std::size_t count, double q) {
    const auto at = v.begin() + std::ptrdiff_t(std::min(count - 1, std::size_t(q * double(count))));
    std::nth_element(v.begin(), at, v.begin() + std::ptrdiff_t(count));
    return *at;
}

}  // namespace

float particle_spacing(ConstPositions p, const float origin[3], float cap, std::uint32_t samples,
                       SpacingWorkspace ws) {
    const std::size_t n = p.size(), s_count = std::min<std::size_t>(samples, n);
    auto sample = [&](std::size_t s) { return s * n / s_count; };

    CellHash h = build_cell_hash(p, origin, cap, ws.heads, ws.order);
    for (std::size_t s = 0; s < s_count; ++s) {
        const std::size_t i = sample(s);
        float best = cap * cap;
        for_each_near(p, h, i, kMaxScan, [&](std::uint32_t j, float dx, float dy, float dz) {
            if (j != i) best = std::min(best, dx * dx + dy * dy + dz * dz);
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
    h = build_cell_hash(p, origin, support, ws.heads, ws.order);
    for (std::size_t s = 0; s < s_count; ++s) {
        double density = 0;
        for_each_near(p, h, sample(s), kMaxScan, [&](std::uint32_t, float dx, float dy, float dz) {
            density += double(w.w(dx * dx + dy * dy + dz * dz));
        });
        ws.values[s] = static_cast<float>(density);
    }
    const float dense = quantile(ws.values, s_count, 0.8);
    return std::min(cap, static_cast<float>(std::cbrt(1.0 / double(dense))));
}

}  // namespace rivulet
