#pragma once
// The motion a voxel gives a particle for one step (Juckel & Beckhaus, "Rendering diffuse objects using
// particle systems inside voxelized surface geometry", §5.1). Each force is integrated exactly over the
// step, not by Euler: a particle that stays in one voxel follows the force's closed-form path whatever
// the frame rate, and the orbit neither gains nor loses energy.
#include <cmath>
#include <cstdint>

#include "jobs/vec3.h"

namespace rivulet {

// A voxel material's force, resolved: kind as DiffuseForce, axis unit length for rotations.
struct VoxelForce {
    std::uint8_t kind = 0;  // DiffuseForce
    Vec3f vector;           // linear: acceleration; spiral, helix: unit axis
    float rate = 0;         // rad/s
    float pull = 0;         // spiral: 1/s towards the axis; helix: m/s along the axis
};

// Turns `d` about the unit `axis` by the angle whose cosine and sine are c, s (Rodrigues).
inline Vec3f rotate_about(Vec3f d, Vec3f axis, float c, float s) {
    return d * c + cross(axis, d) * s + axis * (dot(axis, d) * (1 - c));
}

// The constants of one step of a force: cosines, sines and decays of the step, worked out once per
// material rather than per particle.
struct VoxelStep {
    VoxelForce force;
    float dt = 0;
    float cos_dt = 1, sin_dt = 0;  // of rate * dt
    float decay = 1;               // spiral: exp(-pull dt)
    float drag = 1;                // exp(-drag dt)
};

inline VoxelStep make_voxel_step(const VoxelForce& force, float drag, float dt) {
    VoxelStep s;
    s.force = force;
    s.dt = dt;
    s.cos_dt = std::cos(force.rate * dt), s.sin_dt = std::sin(force.rate * dt);
    s.decay = force.kind == 2 ? std::exp(-force.pull * dt) : 1.0f;
    s.drag = std::exp(-drag * dt);
    return s;
}

// Moves (p, v) by one step under the step's force centred at `centre`, with the particle's own
// velocity damped by the drag and `accel` (scene gravity or wind) acting everywhere.
inline void apply_voxel_step(const VoxelStep& step, Vec3f centre, Vec3f accel, Vec3f& p, Vec3f& v) {
    const VoxelForce& force = step.force;
    const float dt = step.dt;
    Vec3f a = accel;
    if (force.kind == 1) a = a + force.vector;
    if (force.kind == 3) {
        // Harmonic attraction, d'' = -w^2 d + a: an exact rotation in phase space about the centre
        // shifted by a / w^2, where the attraction balances the constant acceleration.
        const float w = force.rate;
        const Vec3f shifted = centre + a * (1 / (w * w));
        const Vec3f d = p - shifted;
        p = shifted + d * step.cos_dt + v * (step.sin_dt / w);
        v = v * step.cos_dt - d * (w * step.sin_dt);
    } else {
        // Constant acceleration integrated exactly.
        p = p + v * dt + a * (0.5f * dt * dt);
        v = v + a * dt;
    }
    v = v * step.drag;
    if (force.kind == 2 || force.kind == 4) {
        // A velocity field that turns about the axis: the particle is carried along it exactly.
        const Vec3f axis = force.vector;
        const Vec3f d = p - centre;
        const float along = dot(d, axis);
        Vec3f turned = rotate_about(d - axis * along, axis, step.cos_dt, step.sin_dt);
        float shift = 0;
        if (force.kind == 2) {
            turned = turned * step.decay;
        } else {
            shift = force.pull * dt;
        }
        p = centre + axis * (along + shift) + turned;
    }
}

// One step of `dt` (tests and tools; jobs keep their VoxelStep).
inline void apply_voxel_force(const VoxelForce& force, Vec3f centre, Vec3f accel, float drag, float dt,
                              Vec3f& p, Vec3f& v) {
    apply_voxel_step(make_voxel_step(force, drag, dt), centre, accel, p, v);
}

}  // namespace rivulet
