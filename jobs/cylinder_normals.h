#pragma once
// Vertex normals of one deformed cylinder range (Hoetzlein & Höllerer 2009 §3.2): each vertex's normal is the
// average of the face normals (area-weighted cross products) of the triangles around it that are drawn this
// frame: bands [vmin, vmax-1], the top cap of vmin and the bottom cap of vmax.
#include <cstdint>
#include <span>

#include "jobs/cylinder_layout.h"

namespace rivulet {

// `vertices`: the cylinder's block, 6 floats per vertex, for a group drawn over rings [vmin, vmax]. Writes
// the normals of rings [first, last] (within [vmin, vmax]) and reads the positions of those rings and of
// their neighbours in the group. Every vertex's sum is added in the same order whatever the range, so
// splitting a cylinder into ranges (run in parallel) gives the same bytes as one call over it all.
void cylinder_normals(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                      std::uint32_t first, std::uint32_t last, std::span<float> vertices);

}  // namespace rivulet
