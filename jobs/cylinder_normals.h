#pragma once
// Vertex normals of one deformed cylinder range (seed 000 §3.2): each vertex's normal is the average of
// the face normals (area-weighted cross products) of the triangles around it that are drawn this frame:
// bands [vmin, vmax-1], the top cap of vmin and the bottom cap of vmax.
#include <cstdint>
#include <span>

#include "jobs/cylinder_layout.h"

namespace rivulet {

// `vertices`: the cylinder's block, 6 floats per vertex; positions of rings [vmin, vmax] are read,
// normals of those rings written.
void cylinder_normals(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                      std::span<float> vertices);

}  // namespace rivulet
