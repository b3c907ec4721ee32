#pragma once
// SPH time integration (semi-implicit Euler: v += a dt, x += v dt) and boundaries. Reads the sorted
// particles and their accelerations, writes the particle store at the same (sorted) index, so the store
// ends the substep ordered by cell with ids alongside. Boundaries are free-slip, inelastic contacts:
// a particle that ends a step inside a static collider (sphere, box) or outside the tank is put back on
// the surface, `margin` away from it, and its velocity component into the surface, relative to the
// surface's own velocity (the moving tank), is removed. Per particle, no neighbours: any split gives the
// same bits.
#include <cstddef>
#include <span>

#include "jobs/ballistic_step.h"
#include "jobs/particle_spans.h"
#include "jobs/sph_grid.h"
#include "jobs/vec3.h"

namespace rivulet {

struct SphBoundary {
    Vec3f tank_min, tank_max;  // inner box the fluid stays in, at the end of this substep
    Vec3f tank_velocity;       // of the tank walls during this substep
    std::span<const SphereObstacle> spheres;
    std::span<const BoxObstacle> boxes;
    float margin = 0;  // distance particle centres keep from every surface (half the spacing)
};

struct SphAccelIn {
    std::span<const float> ax, ay, az;
};

// Advances sorted particles [begin, end) by dt into `out` (same indices); returns the largest |v|^2.
// Empty `accel` spans: the velocities are already the new ones (x += v dt only).
float sph_integrate(const SphParticlesIn& sorted, const SphAccelIn& accel, std::size_t begin, std::size_t end,
                    float dt, const SphBoundary& boundary, const ParticleSpans& out);

}  // namespace rivulet
