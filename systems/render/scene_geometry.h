#pragma once
// CPU-side static geometry of a scene (built once per scene): ground plane, collider solids, pool rim and
// an SPH scene's tank (frame and glass).
#include <cstdint>
#include <span>
#include <vector>

#include "systems/render/frame_view.h"
#include "systems/render/shadow_map.h"
#include "systems/scenes/scene.h"

namespace rivulet {

// Consecutive entries of StaticGeometry::indices.
struct IndexRange {
    std::uint32_t first = 0, count = 0;
};

// 6 floats per vertex (position, normal); one index range per way of drawing. The tank's ranges are empty
// unless the scene is an SPH scene; they are at the container's rest pose.
struct StaticGeometry {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
    IndexRange ground;       // where shadows can fall
    IndexRange ground_far;   // the rest of it
    IndexRange solids;       // colliders and the pool rim, drawn grey
    IndexRange tank_frame;   // the tank's twelve edges as beams, outside the glass
    IndexRange glass_back;   // tank walls seen from inside (behind the fluid): drawn before the fluid
    IndexRange glass_front;  // tank walls seen from outside (in front of it): drawn over it, last
    // A diffuse scene's colliders (sphere or box; mesh colliders are not drawn), each centred on the
    // origin: the renderer draws it at the collider's position of the frame.
    std::vector<IndexRange> movers;
};

// The tank's glass walls enclose this box: the container widened by a particle radius, since the
// fluid's surface lies about that far outside the centres the container holds in. Its floor is the
// ground when the container stands on it (then no glass floor is drawn).
BoxCollider tank_glass_box(const SceneDesc& scene);
// Edge of the tank frame's square beams.
float tank_frame_width(const SceneDesc& scene);

// `shadowed`: the part of the ground that shadows can reach (ShadowFit::ground).
StaticGeometry build_static_geometry(const SceneDesc& scene, GroundRect shadowed);

// Triangle indices of an nx x nz sample grid (row-major, [iz * nx + ix]): (nx-1)*(nz-1)*6 entries.
void write_grid_indices(int nx, int nz, std::span<std::uint32_t> out);

// Positions and normals (from central height differences) of the height field's samples into `out`
// (6 floats per sample, nx*nz samples).
void write_height_field_vertices(const HeightFieldView& field, std::span<float> out);

}  // namespace rivulet
