#pragma once
// Triangle quality of a mesh, for `mesh --json` (issue 18's report): per triangle its smallest angle and
// its radius ratio R / (2 r) (circumradius over twice the inradius: 1 for an equilateral triangle,
// growing without bound as it degenerates). Marching cubes makes slivers where the surface passes close to
// a grid corner; smoothing and the field's shape change how many.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rivulet {

struct MeshQuality {
    std::uint64_t triangles = 0;
    std::uint64_t degenerate = 0;  // zero area (or a vertex index out of range): left out of the rest
    double min_angle_deg = 0;      // the smallest angle of any triangle
    double min_angle_p05 = 0;      // 5 % of the triangles have a smallest angle below this
    double mean_min_angle_deg = 0;
    double median_ratio = 0;  // median radius ratio (a mean would follow the worst slivers' millions)
    double ratio_p95 = 0;     // 95 % of the triangles are at most this
    double max_ratio = 0;
};

// `vertices` holds `stride` floats per vertex, the position first; `indices` three per triangle.
// Serial, in double, in triangle order: the same numbers on every machine.
MeshQuality mesh_quality(std::span<const float> vertices, std::size_t stride,
                         std::span<const std::uint32_t> indices);

}  // namespace rivulet
