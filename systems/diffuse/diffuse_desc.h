#pragma once
// What a diffuse-object scene says about its object: the mesh and grid it is voxelized into, the voxel
// attributes of "Rendering diffuse objects using particle systems inside voxelized surface geometry"
// (Juckel & Beckhaus, §4.2) as a default plus regions that override them, and the colliders that move
// through it (§5.2). Scene files fill these structs (docs/diffuse.md).
#include <cstdint>
#include <string>
#include <vector>

#include "jobs/vec3.h"

namespace rivulet {

// The four forces of §5.1 a voxel can hold. Rotations turn about an axis through the voxel's centre (or,
// with `about_region`, through the centre of the region that set them).
enum class DiffuseForce : std::uint8_t {
    kNone,
    kLinear,  // constant acceleration `vector` (wind, gravity)
    kSpiral,  // turn about `vector` at `rate` rad/s while drawing in at `pull` 1/s: a spiral to the axis
    kOrbit,   // a gravitational point: acceleration -rate^2 (p - centre), an orbit of period 2 pi / rate
    kHelix,   // turn about `vector` at `rate` rad/s while drifting along it at `pull` m/s: a helix
};

// Attributes a field of which below zero means "not set here": a region's unset fields keep the default
// voxel's. Colours are RGBA in [0, 1]; a colour with r < 0 is unset (defaults: the mesh's colour).
struct VoxelAttributesDesc {
    float max_density = -1;   // particles a voxel holds at most
    float fill_time = -1;     // seconds to fill an empty voxel up to max_density
    Vec3f color{-1, -1, -1};  // particle colour (default: the mesh's colour at the voxel)
    float alpha = -1;         // particle opacity
    float size = -1;          // particle diameter, world units
    Vec3f fade_color{-1, -1, -1};
    float fade_alpha = -1;
    float fade_size = -1;
    float lifetime = -1;            // seconds a particle fades for once it leaves the active voxels
    float interpolation_time = -1;  // seconds to reach a new voxel's colour and size
    float drag = -1;                // 1/s: damping of the particle's own velocity
    float jitter = -1;              // m/s: random speed of a new particle
    std::string force = "";         // "", "none", "linear", "spiral", "orbit" or "helix"
    Vec3f force_vector{0, 0, 0};    // linear: acceleration; spiral and helix: the axis
    float force_rate = -1;          // spiral, helix: rad/s; orbit: rad/s of the orbit
    float force_pull = -1;          // spiral: 1/s towards the axis; helix: m/s along it
    bool about_region = false;      // rotations about the region's centre instead of each voxel's
};

// Where a region applies: "box" [min, max], "sphere" (center, radius), or "all" voxels. Later regions
// win over earlier ones.
struct DiffuseRegion {
    std::string shape = "box";
    Vec3f min, max;
    Vec3f center;
    float radius = 0;
    VoxelAttributesDesc attributes;
};

// A solid moving through the object (§5.2): "sphere" (radius), "box" (half_extents) or "mesh" (a file).
// Its centre eases from `from` to `to` and back every `period` seconds (0: it stays at `from`).
struct DiffuseCollider {
    std::string shape = "sphere";
    float radius = 0.1f;
    Vec3f half_extents{0.1f, 0.1f, 0.1f};
    std::string mesh;
    Vec3f from, to;
    float period = 0;
};

// The object blown away: from `start` seconds (negative: never) a wind front sweeps along `wind` at
// `front_speed` m/s from the object's upwind side (0: everywhere at once); behind it the wind acts on the
// particles and the voxels stop emitting, so the shape drifts off and fades.
struct DissolveDesc {
    float start = -1;
    Vec3f wind;
    float front_speed = 0;
};

struct DiffuseDesc {
    // "ghost" (built in code), or a mesh file (OBJ, PLY, glTF: anything Assimp reads), relative to the
    // scene file or the working directory. The mesh must be closed (watertight).
    std::string mesh = "ghost";
    float scale = 1;               // applied to the mesh, then `position` added: where its rest pose stands
    Vec3f position;                // the scene's container_motion moves the object from here (FrameInputs)
    int resolution = 50;           // voxels along the mesh's longest side (the paper: 50)
    VoxelAttributesDesc defaults;  // every voxel inside the mesh; unset fields take built-in defaults
    std::vector<DiffuseRegion> regions;
    std::vector<DiffuseCollider> colliders;
    DissolveDesc dissolve;
    bool additive = false;  // emissive blending (fire) instead of back-to-front alpha
};

}  // namespace rivulet
