#pragma once
// Test oracle for marching slices: the same field (jobs/slice_field.h, summed in the same global particle
// order) polygonised by plain marching cubes over every cube of the full grid, with the same tables.
// Slow and simple on purpose.
#include <array>
#include <cstdint>
#include <vector>

#include "jobs/anisotropic_kernels.h"
#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"

namespace rivulet::test {

struct ReferenceMesh {
    std::vector<float> positions;  // 3 per vertex
    std::vector<std::uint32_t> indices;
};

ReferenceMesh reference_marching_cubes(const SliceGrid& grid, float iso, ConstPositions particles);
// The same with anisotropic kernels: `particles` are the smoothed centres, `shapes` theirs.
ReferenceMesh reference_marching_cubes(const SliceGrid& grid, float iso, ConstPositions particles,
                                       const ConstKernelShapes& shapes);

// Triangles as position triples, each rotated to start at its smallest vertex (orientation kept), sorted.
std::vector<std::array<float, 9>> canonical_triangles(const std::vector<float>& positions, std::size_t stride,
                                                      const std::vector<std::uint32_t>& indices);

}  // namespace rivulet::test
