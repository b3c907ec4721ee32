#pragma once
// The coarse unit sphere shared by the renderer (instanced isolated particles) and mesh export, so a
// particle looks the same in pictures and in exported meshes.
#include <cstdint>
#include <vector>

namespace rivulet {

struct SphereTemplate {
    std::vector<float> positions;        // unit sphere xyz per vertex; also the vertex normals
    std::vector<std::uint32_t> indices;  // triangles, counter-clockwise seen from outside; closed surface
};

// Icosphere with one subdivision: 42 vertices, 80 triangles. Built on first call (thread-safe), then shared.
const SphereTemplate& low_res_sphere();

}  // namespace rivulet
