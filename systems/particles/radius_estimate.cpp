#include "systems/particles/radius_estimate.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace rivulet {

float estimate_particle_radius(ConstPositions p) {
    const std::size_t n = p.size();
    if (n < 2) return 0;
    const std::size_t samples = std::min<std::size_t>(n, 256);
    std::vector<float> nearest;
    nearest.reserve(samples);
    for (std::size_t s = 0; s < samples; ++s) {
        const std::size_t i = s * n / samples;
        float best = std::numeric_limits<float>::infinity();
        for (std::size_t j = 0; j < n; ++j) {
            const float dx = p.x[j] - p.x[i], dy = p.y[j] - p.y[i], dz = p.z[j] - p.z[i];
            const float d2 = dx * dx + dy * dy + dz * dz;
            if (d2 > 0 && d2 < best) best = d2;
        }
        if (std::isfinite(best)) nearest.push_back(std::sqrt(best));
    }
    if (nearest.empty()) return 0;
    const auto mid = nearest.begin() + static_cast<std::ptrdiff_t>(nearest.size() / 2);
    std::nth_element(nearest.begin(), mid, nearest.end());
    return 0.5f * *mid;
}

}  // namespace rivulet
