#pragma once
// What a scene is: emitters, colliders, pool, camera and the extents the surface methods need. Built-in
// scenes are made in code (builtin_scenes.cpp); scene files (docs/scenes.md) fill the same struct.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "jobs/vec3.h"
#include "systems/diffuse/diffuse_desc.h"
#include "systems/scenes/colliders.h"
#include "systems/scenes/scene_look.h"
#include "systems/sim/sph_desc.h"

namespace rivulet {

// A nozzle: particles leave `position` (jittered within `nozzle_radius`) along `direction`, at `speed`,
// inside a cone of half-angle `spread` radians, `rate` particles per second.
struct Emitter {
    Vec3f position;
    Vec3f direction{0, 1, 0};
    float speed = 1;
    float spread = 0;
    float nozzle_radius = 0;
    float rate = 0;
};

// The resting pool: a height field (2D wave equation) over a rectangle, at `level` when calm. A particle
// that reaches it pushes the surface down and is absorbed (Hoetzlein & Höllerer 2009 §3).
struct PoolDesc {
    bool enabled = false;
    float x0 = 0, z0 = 0;          // corner of the rectangle
    float size_x = 1, size_z = 1;  // extent
    int nx = 128, nz = 128;        // grid samples
    float level = 0;               // calm surface height (y)
    float wave_speed = 1.0f;       // m/s
    float damping = 0.5f;          // 1/s
    float impulse_scale = 0.002f;  // depth change per unit of particle downward momentum
    float max_dip = 0.05f;         // impulses never push the surface further than this below `level`
    float drain = 0.3f;            // 1/s: the water the streams bring drains away, so the mean level holds
};

struct CameraDesc {
    Vec3f eye{0, 1.5f, 4};
    Vec3f target{0, 0.8f, 0};
    float fov_y_deg = 45;
};

// The fluid container swinging on its own (a slosh scene): offset = amplitude * sin(2 pi frequency t).
struct ContainerMotion {
    Vec3f amplitude;
    float frequency = 0;  // Hz; 0 = still
};

// Which simulation produces the particles: ballistic streams with a height-field pool
// (Hoetzlein & Höllerer 2009 §3), SPH fluid in a tank (Inácio et al. 2010 §III), or a diffuse object:
// particles living in a voxelized mesh (Juckel & Beckhaus 2007), drawn as sprites rather than as a
// fluid surface.
enum class SimulationKind { kStreams, kSph, kDiffuse };

struct SceneDesc {
    std::string name;
    SimulationKind simulation = SimulationKind::kStreams;
    // SPH scenes: the fluid, its tank and the initial blocks. Gravity, dt, colliders (spheres, boxes) and
    // the container's motion are the scene's own fields below and override the desc's copies.
    SphDesc sph;
    float particle_radius = 0.02f;  // world units
    std::uint32_t max_particles = 16384;
    float dt = 1.0f / 60.0f;  // seconds per frame
    int substeps = 2;
    int warmup_frames = 90;  // simulated before frame 0 so pictures start in the steady state
    std::uint64_t seed = 1;
    float lifetime = 6.0f;  // seconds; older particles are recycled
    Vec3f gravity{0, -9.81f, 0};
    float ground_y = 0;
    float restitution = 0.3f;
    float friction = 0.4f;
    std::vector<Emitter> emitters;
    std::vector<SphereCollider> spheres;
    std::vector<BoxCollider> boxes;
    PoolDesc pool;
    float v_min = 0, v_max = 3;  // extent of the cylinders along +y (scan conversion domain)
    CameraDesc camera;
    ContainerMotion container_motion;  // diffuse scenes: the object's motion
    DiffuseDesc diffuse;               // diffuse scenes: the object, its voxels and colliders
    SceneLook look;                    // water colour and absorption, environment
};

std::span<const std::string_view> builtin_scene_names();
// Throws std::invalid_argument naming the known scenes when `name` is not one of them.
SceneDesc make_builtin_scene(std::string_view name);

}  // namespace rivulet
