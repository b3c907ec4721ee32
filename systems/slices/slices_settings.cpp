#include "systems/slices/slices_settings.h"

#include <fmt/format.h>
#include <cmath>

#include "jobs/slice_field.h"

namespace rivulet {

double calibrated_iso(double rc_factor) {
    const double rc = rc_factor, d = 2.0;
    const int reach = static_cast<int>(std::ceil(rc / d)) + 1;
    double total = 0;
    for (int a = 0; a < 8; ++a)
        for (int b = 0; b < 8; ++b) {
            const double px = d * a / 8.0, py = d * b / 8.0, pz = 1.0;
            double field = 0;
            for (int k = 0; k <= reach; ++k)
                for (int j = -reach; j <= reach + 1; ++j)
                    for (int i = -reach; i <= reach + 1; ++i) {
                        const double dx = px - d * i, dy = py - d * j, dz = pz + d * k;
                        const double r2 = dx * dx + dy * dy + dz * dz;
                        if (r2 >= rc * rc) continue;
                        const double q = r2 / (2 * rc * rc) - 0.5;
                        field += q * q;
                    }
            total += field;
        }
    return total / 64.0;
}

float SlicesSettings::iso_value() const {
    return iso > 0 ? iso : static_cast<float>(calibrated_iso(rc_factor));
}

std::string SlicesSettings::validate() const {
    if (!(radius > 0) || !std::isfinite(radius))
        return fmt::format("--radius must be a positive number, got {}", radius);
    if (!std::isfinite(voxel) || voxel < 0) return fmt::format("--voxel must be positive, got {}", voxel);
    if (voxel_size() > 4 * radius)
        return fmt::format(
            "--voxel {} is coarser than 4 particle radii ({}): the surface would lose particles",
            voxel_size(), 4 * radius);
    if (block_cubes < 2 || block_cubes > kMaxBlockCubes)
        return fmt::format("--block must be in [2, {}] cubes, got {}", kMaxBlockCubes, block_cubes);
    if (!(rc_factor >= 1.0f && rc_factor <= 8.0f))
        return fmt::format("R_c factor must be in [1, 8], got {}", rc_factor);
    // The lookup cache packs a particle's reach box into 16-bit rows (and a finer voxel is absurd: a
    // particle would touch millions of corners).
    if (rc() / voxel_size() > float(kMaxReach))
        return fmt::format("--voxel {} is finer than R_c / {} ({}): a particle would reach too many corners",
                           voxel_size(), kMaxReach, rc() / float(kMaxReach));
    if (!std::isfinite(iso) || iso < 0) return fmt::format("iso threshold must be positive, got {}", iso);
    if (iso >= 0.25f * 64) return fmt::format("iso threshold {} is unreachable by the field", iso);
    if (max_blocks == 0 || max_triangles == 0 || max_grid_cubes == 0)
        return "slices limits (max_blocks, max_triangles, max_grid_cubes) must be positive";
    if (max_grid_cubes > (1u << 20)) return "max_grid_cubes must be at most 2^20";
    return {};
}

}  // namespace rivulet
