#pragma once
// Everything the SPH fluid (Müller, Charypar & Gross 2003; Inácio et al. 2010 §III) needs: resolution, fluid
// constants, equation of state, the tank and its motion, colliders, the initial fluid and time stepping.
// Units are SI (m, kg, s). docs/sph.md explains each parameter.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/vec3.h"
#include "systems/scenes/colliders.h"

namespace rivulet {

// A block of fluid filled on a cubic lattice of the desc's spacing: a box [min, max], or a sphere.
struct SphFluidBox {
    Vec3f min, max;
    Vec3f velocity;
};
struct SphFluidSphere {
    Vec3f center;
    float radius = 0;
    Vec3f velocity;
};

// The container: an axis-aligned box (the tank) whose offset is
//   user offset (SphSimulation::set_container_offset) + amplitude * axis * sin(2 pi frequency t).
struct SphContainer {
    BoxCollider box;  // at offset 0
    Vec3f axis{1, 0, 0};
    float amplitude = 0;  // m
    float frequency = 0;  // Hz
};

// The pressure solver. DFSPH (divergence-free SPH, Bender & Koschier 2015/2017) keeps the fluid
// incompressible to a set density error with substeps limited by the particles' speed only; WCSPH (Tait
// equation of state, Müller 2003 forces) is the weakly compressible solver whose substeps are limited by
// the numerical sound speed.
enum class SphSolver { kDfsph, kWcsph };

struct SphDesc {
    std::string name = "sph";
    SphSolver solver = SphSolver::kDfsph;
    // Resolution: lattice spacing of the initial fluid and kernel support radius h = support_ratio * spacing.
    float spacing = 0.02f;
    float support_ratio = 2.0f;
    // Fluid. Particle mass is set so the poly6 density of an unbounded lattice of `spacing` equals
    // rest_density exactly.
    float rest_density = 1000.0f;  // kg/m^3
    // Equation of state (Tait, weakly compressible): p = B ((rho / rho0)^gamma - 1), B = rho0 c0^2 / gamma,
    // clamped at p >= 0 (no tension from particle deficiency at free surfaces). c0 is a numerical sound
    // speed, about 10x the largest flow speed, which keeps density variation near 1 %.
    float sound_speed = 20.0f;  // c0, m/s
    float gamma = 7.0f;
    float viscosity = 0.01f;  // mu of Müller's viscosity term, Pa s
    // Monaghan artificial viscosity alpha (approaching pairs only): damps the acoustic noise of the weakly
    // compressible fluid; 0.02-0.1 is usual.
    float artificial_viscosity = 0.05f;
    bool surface_tension = false;
    float tension = 0.0728f;           // sigma, N/m (colour-field force of Müller 2003 §4.4)
    float tension_threshold = 7.065f;  // |grad c| above which the force acts, 1/m
    Vec3f gravity{0, -9.81f, 0};
    // Boundaries: the tank (free slip, moving with the container) and static colliders (free slip).
    SphContainer container;
    // Tank walls as mirror images of the neighbours (jobs/sph_density.h SphWalls); off: only the hard
    // constraint holds the fluid in (it then packs against the walls).
    bool wall_pressure = true;
    std::vector<SphereCollider> spheres;
    std::vector<BoxCollider> boxes;
    // Initial fluid.
    std::vector<SphFluidBox> fluid_boxes;
    std::vector<SphFluidSphere> fluid_spheres;
    // DFSPH: the average density error each substep's pressure solve leaves (percent of rest density),
    // and the average density change per substep its divergence solve leaves (percent); at most
    // max_iterations iterations each. The divergence bound is looser than the density bound (and than
    // SPlisHSPlasH's 0.1): a divergence iteration costs a correction and a look again, and the density
    // solve removes what it leaves for less (docs/sph.md, step 2).
    float max_density_error = 0.1f;
    float max_divergence_error = 0.3f;
    int max_iterations = 100;
    // DFSPH: both solves' relaxed Jacobi iterations are accelerated by Chebyshev's semi-iterative method
    // with this estimate of the iteration's spectral radius (jobs/dfsph_solve.h); 0: plain Jacobi.
    float chebyshev = 0.8f;
    // Time: one frame is `dt`, split into substeps by the CFL condition (WCSPH: equal substeps with
    // dt_sub <= cfl * h / (c0 + v_max) and the force condition 0.25 sqrt(h / a_max), from the frame's
    // start; DFSPH: each substep from the speeds at its start, dt_sub <= cfl * spacing / v_max, v_max
    // including the substep's gravity and the walls' speed, the frame's time left split evenly) and the
    // viscous condition 0.125 h^2 rho0 / mu, at most max_substeps. cfl 0 takes the solver's own number
    // (step_cfl). The WCSPH-only keys (sound_speed, gamma, artificial_viscosity, tension) are ignored by
    // DFSPH. Simulated time always advances by dt per frame: if max_substeps is too small the substeps
    // exceed those limits and the fluid can blow up.
    float dt = 1.0f / 60.0f;
    float cfl = 0.0f;
    int max_substeps = 64;
    // Framing for the renderer: a box holding the tank over its whole motion.
    BoxCollider bounds;

    float support() const { return support_ratio * spacing; }
    // The CFL number the substeps use: `cfl`, or where that is 0 the solver's: DFSPH 0.75 spacing a
    // substep (its solves hold the density at any step, but from 0.85 on a coarse dam break gains energy
    // at its impacts; docs/sph.md), WCSPH 0.4 of h over the sound speed (an explicit step must resolve
    // the pressure waves).
    float step_cfl() const { return cfl > 0.0f ? cfl : solver == SphSolver::kDfsph ? 0.75f : 0.4f; }
};

// Number of particles seeding `desc` places (lattice points inside its fluid boxes and spheres), counted
// without visiting them; any count over kMaxSceneParticles (scene_limits.h) comes back as
// kMaxSceneParticles + 1.
std::size_t sph_seed_count(const SphDesc& desc);

}  // namespace rivulet
