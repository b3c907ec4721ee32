#pragma once
// CPU-side static geometry of a scene (built once per scene): ground plane, collider solids, pool rim.
#include <cstdint>
#include <span>
#include <vector>

#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"

namespace rivulet {

// 6 floats per vertex (position, normal). Ground triangles come first, then everything drawn grey.
struct StaticGeometry {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
    std::uint32_t ground_index_count = 0;
};

StaticGeometry build_static_geometry(const SceneDesc& scene);

// Triangle indices of an nx x nz sample grid (row-major, [iz * nx + ix]): (nx-1)*(nz-1)*6 entries.
void write_grid_indices(int nx, int nz, std::span<std::uint32_t> out);

// Positions and normals (from central height differences) of the height field's samples into `out`
// (6 floats per sample, nx*nz samples).
void write_height_field_vertices(const HeightFieldView& field, std::span<float> out);

}  // namespace rivulet
