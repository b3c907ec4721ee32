#pragma once
// The mesh of the cubes a marching-slices sweep visited in one slab (jobs/marching_slices.h): a vertex on
// each crossed edge of those cubes that has none yet, then their triangles, row by row. Apart from the
// sweep's flood so that this part, which needs no vector build, is compiled once and gets a small
// function of its own.
#include <cstdint>

#include "jobs/marching_slices.h"

namespace rivulet {

struct SlabMesh {
    // The block: cubes per edge, corner origin, and whether it is the last block of the grid per axis
    // (a corner on a max plane belongs to the next block otherwise).
    std::uint32_t n = 0;
    std::int32_t i0 = 0, j0 = 0, k0 = 0;
    bool last[3] = {false, false, false};
    float voxel = 1, iso = 0;
    const float* plane_x = nullptr;  // world x, y, z of the block's corner planes (n + 1 each)
    const float* plane_y = nullptr;
    const float* plane_z = nullptr;
    // The slab k between slices k and k + 1: their corner values and rows of inside corners (row_words(n)
    // words a row), the rows [row_lo, row_hi] of visited cubes.
    std::uint32_t k = 0;
    const float* lower = nullptr;
    const float* upper = nullptr;
    const std::uint64_t* inside_lower = nullptr;
    const std::uint64_t* inside_upper = nullptr;
    const std::uint64_t* visit = nullptr;
    std::int32_t row_lo = 0, row_hi = -1;
    // Per slice and axis, rows of the edges that have a vertex (SliceScratch::edge_rows), and the vertex
    // of each such edge (SliceScratch::edges).
    std::uint64_t* made = nullptr;
    std::uint32_t* edges = nullptr;
    const std::uint32_t* edge_offset = nullptr;  // 12: slot of each cube edge relative to the cube's first
    BlockMeshOut out;
    std::uint32_t max_vertices = 0, max_triangles = 0;
};

// Creates the vertices (SlabMesh::made and edges updated; st counts them) and returns false when the
// output was too small (st.overflow set).
template <int W>
bool create_slab_vertices(const SlabMesh& m, BlockSweepStats& st);
// Writes the visited cubes' triangles (st.triangles and st.cubes count them); false on overflow.
template <int W>
bool write_slab_triangles(const SlabMesh& m, BlockSweepStats& st);

}  // namespace rivulet
