#include "systems/slices/slices_settings.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>

#include "jobs/slice_field.h"

namespace rivulet {

const char* slice_field_name(SliceField field) {
    return field == SliceField::kClassic ? "classic" : "spacing";
}

bool parse_slice_field(const std::string& name, SliceField& out) {
    if (name == "spacing") return out = SliceField::kSpacing, true;
    if (name == "classic") return out = SliceField::kClassic, true;
    return false;
}

double lattice_mean_field(double rc_factor, double spacing) {
    const double rc = rc_factor, d = spacing;
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

double calibrated_iso(double rc_factor) {
    return lattice_mean_field(rc_factor, 2.0);
}

double lone_particle_iso(double rc_factor) {
    const double a = 1.0 - 1.0 / (rc_factor * rc_factor);
    return 0.25 * a * a;
}

SpacingField spacing_field(double spacing) {
    const double d =
        std::isnan(spacing) ? kMaxFieldSpacing : std::clamp(spacing, kMinFieldSpacing, kMaxFieldSpacing);
    // The mean lattice field one radius up minus the lone particle's iso rises with R_c: negative near
    // 1 (where hardly more than the particle below reaches), positive at 1.5 + d / 2 for every spacing
    // in range (test SpacingField.BisectionBracketsItsRootAndRcGrowsWithSpacing; the root runs from 1.03 at d
    // = 1/4 to 2.20 at d = 2). Bisection in double: the same answer on every machine.
    double lo = 1.0, hi = spacing_field_rc_bound(d);
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (lattice_mean_field(mid, d) > lone_particle_iso(mid) ? hi : lo) = mid;
    }
    const double rc = 0.5 * (lo + hi);
    return {d, rc, lone_particle_iso(rc)};
}

SliceFieldValues SlicesSettings::field_values(float data_spacing) const {
    if (field == SliceField::kClassic)
        return {rc_factor * radius, iso > 0 ? iso : static_cast<float>(calibrated_iso(rc_factor)), 0.0f};
    const float d = spacing > 0 ? spacing : data_spacing;
    const SpacingField f = spacing_field(double(d) / double(radius));
    return {static_cast<float>(f.rc_factor) * radius, static_cast<float>(f.iso),
            static_cast<float>(f.spacing) * radius};
}

float SlicesSettings::max_rc() const {
    if (field == SliceField::kClassic) return rc_factor * radius;
    return static_cast<float>(spacing_field_rc_bound(kMaxFieldSpacing)) * radius;
}

std::string SlicesSettings::validate() const {
    if (!(radius > 0) || !std::isfinite(radius))
        return fmt::format("--radius must be a positive number, got {}", radius);
    // The field squares distances in float: below this R_c^2 nears the smallest normal float and a
    // frame would mesh to nothing, silently.
    if (radius < 1e-15f)
        return fmt::format("--radius {} is too small (at least 1e-15: scale the data up)", radius);
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
    if (!(anisotropy == 0 || (anisotropy >= 1 && anisotropy <= kMaxAnisotropy)))
        return fmt::format(
            "--anisotropic must be in [1, {}] (the longest kernel axis over the shortest), got {}",
            kMaxAnisotropy, anisotropy);
    if (!(anisotropy_smoothing >= 0 && anisotropy_smoothing <= 1))
        return fmt::format("anisotropy_smoothing must be in [0, 1], got {}", anisotropy_smoothing);
    if (max_rc() * reach_factor() / voxel_size() > float(kMaxReach))
        return fmt::format(
            "--voxel {} is finer than the kernel's reach / {} ({}): a particle would reach too "
            "many corners",
            voxel_size(), kMaxReach, max_rc() * reach_factor() / float(kMaxReach));
    if (!std::isfinite(spacing) || spacing < 0)
        return fmt::format("--spacing must be a positive number, got {}", spacing);
    if (field != SliceField::kSpacing && field != SliceField::kClassic) return "unknown slices field";
    if (!std::isfinite(iso) || iso < 0) return fmt::format("iso threshold must be positive, got {}", iso);
    if (iso >= 0.25f * 64) return fmt::format("iso threshold {} is unreachable by the field", iso);
    if (max_blocks == 0 || max_triangles == 0 || max_grid_cubes == 0)
        return "slices limits (max_blocks, max_triangles, max_grid_cubes) must be positive";
    if (max_grid_cubes > (1u << 20)) return "max_grid_cubes must be at most 2^20";
    return {};
}

}  // namespace rivulet
