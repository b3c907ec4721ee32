#pragma once
// One frame's marching-slices output: an indexed triangle mesh, 6 floats per vertex (position, normal),
// triangles counter-clockwise seen from outside the fluid. Lives in a frame slot; capacity grows rarely.
#include <cstdint>

#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"

namespace rivulet {

struct SurfaceMesh {
    AlignedArray<float> vertices6;
    AlignedArray<std::uint32_t> indices;
    std::size_t vertex_count = 0, index_count = 0;

    std::size_t triangle_count() const { return index_count / 3; }
    TriangleMeshView view() const { return {vertices6.span(vertex_count * 6), indices.span(index_count)}; }
};

}  // namespace rivulet
