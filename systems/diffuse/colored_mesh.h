#pragma once
// A triangle mesh with optional per-vertex colour: what diffuse objects are voxelized from, and what mesh
// colliders are made of.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace rivulet {

struct ColoredMesh {
    std::vector<float> positions;        // xyz per vertex
    std::vector<float> colors;           // rgb in [0, 1] per vertex; empty when the mesh has none
    std::vector<std::uint32_t> indices;  // three per triangle, counter-clockwise seen from outside
    std::size_t vertex_count() const { return positions.size() / 3; }
    std::size_t triangle_count() const { return indices.size() / 3; }
};

}  // namespace rivulet
