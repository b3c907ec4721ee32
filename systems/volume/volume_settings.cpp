#include "systems/volume/volume_settings.h"

#include <cmath>
#include <numbers>

#include <fmt/format.h>

namespace rivulet {

double calibrated_volume_iso(double kernel_radii) {
    // Radius 1: spacing 2, V = 8, top layer at y = 0, points at y = 1.
    const double h = kernel_radii, h2 = h * h;
    const double scale = 8.0 * 315.0 / (64.0 * std::numbers::pi * h2 * h2 * h2 * h2 * h);
    const int reach = static_cast<int>(std::ceil(h / 2.0)) + 1;
    double sum = 0;
    for (int sz = 0; sz < 8; ++sz)
        for (int sx = 0; sx < 8; ++sx) {
            const double px = 2.0 * (sx + 0.5) / 8.0, pz = 2.0 * (sz + 0.5) / 8.0;
            for (int k = -reach; k <= reach + 1; ++k)
                for (int j = -reach; j <= 0; ++j)
                    for (int i = -reach; i <= reach + 1; ++i) {
                        const double dx = 2.0 * i - px, dy = 2.0 * j - 1.0, dz = 2.0 * k - pz;
                        const double r2 = dx * dx + dy * dy + dz * dz;
                        if (r2 < h2) sum += scale * std::pow(h2 - r2, 3);
                    }
        }
    return sum / 64.0;
}

float VolumeSettings::iso_value() const {
    return iso > 0 ? iso : static_cast<float>(calibrated_volume_iso(kernel_radii));
}

DensityGridParams VolumeSettings::grid_params() const {
    DensityGridParams r;
    r.h = h();
    r.volume = particle_volume();
    r.voxel = voxel > 0 ? voxel : 0;
    r.max_dim = max_dim;
    return r;
}

std::string VolumeSettings::validate() const {
    if (!(radius > 0) || !std::isfinite(radius))
        return fmt::format("--radius must be positive, got {}", radius);
    if (!(kernel_radii >= 1.0f && kernel_radii <= 16.0f))
        return fmt::format("--kernel must be in [1, 16] particle radii, got {}", kernel_radii);
    if (!std::isfinite(voxel) || voxel < 0) return fmt::format("--voxel must be positive, got {}", voxel);
    if (voxel > 0 && voxel > h())
        return fmt::format("--voxel {} is larger than the kernel radius {}: the volume would miss particles",
                           voxel, h());
    if (max_dim < 16 || max_dim > 2048 || max_dim % 8 != 0)
        return fmt::format("--max-dim must be a multiple of 8 in [16, 2048], got {}", max_dim);
    if (!std::isfinite(iso) || iso < 0 || iso > 100)
        return fmt::format("--iso must be in (0, 100], got {}", iso);
    if (max_bricks < 1 || max_bricks > (1u << 22))
        return fmt::format("max_bricks must be in [1, {}], got {}", 1u << 22, max_bricks);
    return {};
}

}  // namespace rivulet
