#include "jobs/isolated_particles.h"

namespace rivulet {

std::uint32_t collect_isolated(ConstPositions p, std::span<const std::uint8_t> grouped,
                               std::span<float> centers) {
    std::uint32_t n = 0;
    for (std::size_t i = 0; i < grouped.size(); ++i) {
        if (grouped[i]) continue;
        centers[3 * n] = p.x[i], centers[3 * n + 1] = p.y[i], centers[3 * n + 2] = p.z[i];
        ++n;
    }
    return n;
}

}  // namespace rivulet
