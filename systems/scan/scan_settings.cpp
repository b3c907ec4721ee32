#include "systems/scan/scan_settings.h"

#include <algorithm>

#include <fmt/format.h>
#include <cmath>

#include "jobs/deform_cylinder.h"

namespace rivulet {

void ScanSettings::fit_v_range(std::span<const float> y) {
    const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
    v_top = *hi + 0.5f * radius;
    v_bottom = *lo - 0.5f * radius;
}

std::string ScanSettings::validate() const {
    if (u < 3 || u > kMaxRingVertices)
        return fmt::format("--u must be in [3, {}], got {}", kMaxRingVertices, u);
    if (v < 2 || v > 8192) return fmt::format("--v must be in [2, 8192], got {}", v);
    if (max_groups < 1 || max_groups > 100000)
        return fmt::format("max groups must be in [1, 100000], got {}", max_groups);
    if (!std::isfinite(radius) || radius <= 0)
        return fmt::format("--radius must be a positive number, got {}", radius);
    const float eps = grouping_distance();
    if (!std::isfinite(eps) || eps <= 0)
        return fmt::format("grouping distance must be positive, got {}", eps);
    if (section.smoothing_iterations < 0 || section.smoothing_iterations > 10000)
        return fmt::format("smoothing iterations must be in [0, 10000], got {}",
                           section.smoothing_iterations);
    if (!std::isfinite(section.tension) || section.tension < 0)
        return fmt::format("tension k must be >= 0, got {}", section.tension);
    if (!std::isfinite(v_top) || !std::isfinite(v_bottom) || !(v_top > v_bottom))
        return fmt::format("V domain must have top > bottom, got [{}, {}]", v_bottom, v_top);
    const double spacing = (double(v_top) - double(v_bottom)) / double(v - 1);
    if (double(radius) / spacing > 4096)
        return fmt::format(
            "radius {} spans more than 4096 cross-sections of spacing {}: raise --v or lower --radius",
            radius, spacing);
    return {};
}

}  // namespace rivulet
