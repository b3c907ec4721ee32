#pragma once
// What the renderer reads from a frame slot. Views only: the slot owns the memory, and the renderer
// copies what it needs into GL buffers before the slot is handed back to the workers.
#include <cstdint>
#include <span>

#include "jobs/cylinder_layout.h"
#include "jobs/density_volume.h"
#include "jobs/diffuse_particles.h"

namespace rivulet {

// Heights of the pool surface, row-major [iz * nx + ix], absolute y. Sample (ix, iz) lies at
// (x0 + ix * dx, z0 + iz * dz).
struct HeightFieldView {
    int nx = 0, nz = 0;
    float x0 = 0, z0 = 0, dx = 1, dz = 1;
    std::span<const float> heights;
};

// Scan-conversion output: the whole cylinder pool's vertex array of this slot (6 floats per vertex:
// position xyz, normal xyz; cylinder c starts at vertex c * layout.verts_per_cylinder()) and the groups
// drawn this frame. Only rings [vmin, vmax] of a drawn cylinder are valid and need uploading.
struct CylinderFrameView {
    std::span<const float> vertices;
    std::span<const GroupDraw> groups;
};

// A general indexed triangle mesh (6 floats per vertex: position, normal), e.g. from marching slices.
struct TriangleMeshView {
    std::span<const float> vertices;
    std::span<const std::uint32_t> indices;
};

// Particle centres for the screen-space fluid pass, one array per coordinate.
struct ParticleSpritesView {
    std::span<const float> x, y, z;
    std::size_t size() const { return x.size(); }
};

// A frame's diffuse-object particles and the order to draw them in: `order` lists their indices back to
// front (drawn through an index buffer, so the sorted sprites are never gathered on the CPU), or is
// empty to draw them as they lie. `additive`: emissive blending (fire), order-free.
struct DiffuseSpritesView {
    std::span<const DiffuseSprite> sprites;
    std::span<const std::uint32_t> order;
    bool additive = false;
};

struct FrameView {
    CylinderFrameView cylinders;
    TriangleMeshView mesh;
    std::span<const float> sphere_centers;  // xyz per isolated particle, drawn as instanced low-res spheres
    float sphere_radius = 0;
    ParticleSpritesView sprites;  // drawn by the screen-space fluid pass, as spheres of sphere_radius
    float sprite_spacing = 0;     // the sprites' spacing (0: unknown): screen_depth_radius
    // Whether the shadow pass draws the mesh. A method that gives its particles as `sprites` for the
    // shadow may leave the mesh out of it: the shadow pass shades vertices on the render thread alone,
    // and a splashing frame's mesh has about 40 times the vertices of its particles.
    bool mesh_casts_shadow = true;
    // Isolated particles the screen-space fluid pass draws as small bright sprites after the water (not
    // part of its depth or thickness); empty unless the method splits spray off.
    ParticleSpritesView spray;
    HeightFieldView pool;
    DiffuseSpritesView diffuse;
    // The density volume, raycast as water after the scene (Renderer::set_volume_raycast); nothing is
    // drawn for it while it stores no bricks.
    DensityVolumeView volume;
};

}  // namespace rivulet
