#pragma once
// One frame of ballistic particle motion (Hoetzlein & Höllerer 2009 §3): gravity, semi-implicit Euler
// substeps, contacts with a ground plane, spheres and boxes, absorption by a height-field surface. Each
// particle's result depends on that particle and the read-only inputs alone, so any split of the range
// gives the same bits.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"
#include "jobs/vec3.h"

namespace rivulet {

struct SphereObstacle {
    Vec3f center;
    float radius = 0;
};

struct BoxObstacle {
    Vec3f min, max;
};

// Absolute surface heights, row-major [iz * nx + ix], sample (ix, iz) at (x0 + ix * dx, z0 + iz * dz).
// nx == 0 means there is no surface.
struct SurfaceGrid {
    int nx = 0, nz = 0;
    float x0 = 0, z0 = 0, dx = 1, dz = 1;
    const float* heights = nullptr;

    bool covers(float x, float z) const {
        return nx > 0 && x >= x0 && z >= z0 && x <= x0 + static_cast<float>(nx - 1) * dx &&
               z <= z0 + static_cast<float>(nz - 1) * dz;
    }
    // Bilinear; (x, z) must be covered.
    float sample(float x, float z) const;
};

enum ParticleFate : std::uint8_t { kAlive = 0, kAbsorbed = 1, kRecycled = 2 };

struct BallisticParams {
    Vec3f gravity{0, -9.81f, 0};
    float dt = 1.0f / 60.0f;  // one frame
    int substeps = 1;
    float radius = 0.02f;
    float ground_y = 0;
    float restitution = 0.3f;
    float friction = 0.4f;
    std::span<const SphereObstacle> spheres;
    std::span<const BoxObstacle> boxes;
    SurfaceGrid surface;
    // Touching the ground slower than this at the end of the frame counts as resting.
    float rest_speed = 0.2f;
    Vec3f bounds_min{-1e3f, -1e3f, -1e3f}, bounds_max{1e3f, 1e3f, 1e3f};
    std::uint32_t now = 0;      // frame stamp compared with `birth`
    std::uint32_t max_age = 0;  // frames; a particle this old is recycled without moving
};

// Per particle index: fate, and where / how hard an absorbed particle hit the surface (downward momentum
// per unit mass). Hit slots of particles that did not hit are left untouched.
struct BallisticOutputs {
    std::span<std::uint8_t> fate;
    std::span<float> hit_x, hit_z, hit_momentum;
};

// Advances particles [begin, end) by params.dt and writes their fate.
void ballistic_step(const ParticleSpans& particles, std::span<const std::uint32_t> birth, std::size_t begin,
                    std::size_t end, const BallisticParams& params, const BallisticOutputs& out);

}  // namespace rivulet
