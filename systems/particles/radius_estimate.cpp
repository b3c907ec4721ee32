#include "systems/particles/radius_estimate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace rivulet {

float estimate_particle_radius(ConstPositions p) {
    const std::size_t n = p.size();
    if (n < 2) return 0;
    constexpr std::size_t kSamples = 256;
    const std::size_t samples = std::min(n, kSamples);
    std::array<float, kSamples> nearest;  // no allocation: the library estimates once per call
    std::size_t found = 0;
    for (std::size_t s = 0; s < samples; ++s) {
        const std::size_t i = s * n / samples;
        float best = std::numeric_limits<float>::infinity();
        for (std::size_t j = 0; j < n; ++j) {
            const float dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i], dz = p.z[j] - p.z[i];
            const float d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > 0 && d2 < best) best = d2;
        }
        if (std::isfinite(best)) nearest[found++] = std::sqrt(best);
    }
    if (found == 0) return 0;
    const auto mid = nearest.begin() + static_cast<std::ptrdiff_t>(found / 2);
    std::nth_element(nearest.begin(), mid, nearest.begin() + static_cast<std::ptrdiff_t>(found));
    return 0.5f * *mid;
}

}  // namespace rivulet
