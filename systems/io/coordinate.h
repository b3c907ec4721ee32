#pragma once
// Double to float for coordinates read from files.
#include <cmath>
#include <limits>

namespace rivulet::io {

// Values beyond float range become infinite instead of undefined behaviour, so they are reported by the
// readers' non-finite check rather than turning into garbage.
inline float narrow_coordinate(double v) {
    if (std::fabs(v) <= static_cast<double>(std::numeric_limits<float>::max())) return static_cast<float>(v);
    if (std::isnan(v)) return std::numeric_limits<float>::quiet_NaN();
    return v > 0 ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
}

}  // namespace rivulet::io
