#pragma once
// The voxel steps of an object's materials (jobs/diffuse_forces.h) laid out for the update's vector lanes:
// one row per quantity, one column per material and the outside step last, so eight lanes pick their
// materials' values with one permute (or a lookup per lane where there are more than eight columns).
// Every quantity the step derives from its force (1 / w^2, sin / w, ...) is worked out here once, by the
// same operations apply_voxel_step does, so the lanes give the scalar step's bits.
#include <cstddef>
#include <span>
#include <vector>

#include "jobs/diffuse_particles.h"

namespace rivulet {

enum DiffuseStepRow : int {
    kStepLinear,       // 1: the force adds its vector to the acceleration
    kStepOrbit,        // 1: harmonic attraction about the centre
    kStepTurn,         // 1: spiral or helix, a turn about the axis through the centre
    kStepCentred,      // 1: the force has a centre (spiral, orbit, helix)
    kStepAboutRegion,  // 1: that centre is the region's, else the particle's voxel's
    kStepVectorX,
    kStepVectorY,
    kStepVectorZ,
    kStepDt,
    kStepHalfDt2,   // 0.5 dt dt
    kStepInvW2,     // orbit: 1 / w^2
    kStepSinOverW,  // orbit: sin(w dt) / w
    kStepWSin,      // orbit: w sin(w dt)
    kStepCos,
    kStepSin,
    kStepOneMinusCos,
    kStepDecay,
    kStepShift,  // helix: pull dt; else 0
    kStepDrag,
    kStepCentreX,  // the region's centre (object space)
    kStepCentreY,
    kStepCentreZ,
    kStepRows
};

// Columns for `materials` materials and the outside step: a multiple of eight.
inline std::size_t diffuse_step_columns(std::size_t materials) {
    return (materials + 1 + 7) / 8 * 8;
}

// Row-major, kStepRows x diffuse_step_columns(materials.size()); column materials.size() is `outside`.
inline std::vector<float> make_diffuse_step_table(std::span<const VoxelMaterial> materials,
                                                  const VoxelStep& outside) {
    const std::size_t columns = diffuse_step_columns(materials.size());
    std::vector<float> table(kStepRows * columns, 0.0f);
    for (std::size_t k = 0; k <= materials.size(); ++k) {
        const bool is_outside = k == materials.size();
        const VoxelStep& s = is_outside ? outside : materials[k].step;
        const VoxelForce& f = s.force;
        const float w = f.rate;
        const auto set = [&](int row, float value) { table[std::size_t(row) * columns + k] = value; };
        set(kStepLinear, f.kind == 1);
        set(kStepOrbit, f.kind == 3);
        set(kStepTurn, f.kind == 2 || f.kind == 4);
        set(kStepCentred, f.kind >= 2);
        set(kStepAboutRegion, !is_outside && materials[k].about_region);
        set(kStepVectorX, f.vector.x), set(kStepVectorY, f.vector.y), set(kStepVectorZ, f.vector.z);
        set(kStepDt, s.dt), set(kStepHalfDt2, 0.5f * s.dt * s.dt);
        set(kStepInvW2, 1 / (w * w)), set(kStepSinOverW, s.sin_dt / w), set(kStepWSin, w * s.sin_dt);
        set(kStepCos, s.cos_dt), set(kStepSin, s.sin_dt), set(kStepOneMinusCos, 1 - s.cos_dt);
        set(kStepDecay, f.kind == 2 ? s.decay : 1.0f);
        set(kStepShift, f.kind == 4 ? f.pull * s.dt : 0.0f);
        set(kStepDrag, s.drag);
        if (!is_outside) {
            const Vec3f c = materials[k].region_centre;
            set(kStepCentreX, c.x), set(kStepCentreY, c.y), set(kStepCentreZ, c.z);
        }
    }
    return table;
}

}  // namespace rivulet
