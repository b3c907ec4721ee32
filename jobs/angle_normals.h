#pragma once
// Angle-weighted vertex normals (seed 004 §3.2.5): each triangle adds its unit face normal to each of its
// vertices weighted by the triangle's angle at that vertex, so long thin triangles do not dominate.
#include <cstdint>
#include <span>

namespace rivulet {

// acc3[3 v ..] = sum over triangles of (angle at v) * (unit face normal), for positions3 / triangles
// (3 indices each). acc3 is overwritten (3 floats per vertex). Degenerate triangles add nothing.
void accumulate_angle_normals(std::span<const float> positions3, std::span<const std::uint32_t> triangles,
                              std::span<float> acc3);

// Normalises n (3 floats) in place; a zero vector becomes (0, 1, 0), +y up.
void normalize_or_up(float* n);

}  // namespace rivulet
