#pragma once
// One frame meshed in pieces (`mpirun -n K rivulet mesh FRAME --decompose`; docs/cluster.md): marching
// slices' block grid, fixed by the whole frame, is cut into K slabs of whole blocks along its longest
// axis with about equal particles each. Piece r is extracted from the particles of slab r plus a ghost
// margin (a block and a particle's reach on each side), so the blocks next to the slab see every
// particle they would in the whole frame; the piece keeps its slab's triangles only. Welded together by
// their vertices (position and normal, bit for bit), the pieces are the whole frame's mesh as a set of
// triangles, watertight across the slab seams.
#include <cstdint>
#include <span>
#include <vector>

#include "runtime/lib/mesh_extraction.h"

namespace rivulet {

struct MeshPiece {
    std::vector<float> vertices;                   // 6 floats per vertex: position, normal
    std::vector<std::uint32_t> indices;            // the slab's triangles, in block order
    std::size_t particles = 0;                     // particles extracted: the slab's and its ghosts
    int axis = 0;                                  // the axis the slabs cut
    std::uint32_t first_block = 0, end_block = 0;  // the slab: blocks [first, end) along `axis`
    double extract_ms = 0;                         // the piece's extraction, ghosts included
    // The slab's faces along `axis` (world) and the voxel: only vertices within a voxel of a face can
    // be another piece's too.
    float face_lo = 0, face_hi = 0, voxel = 0;
};

// Piece `piece` of `pieces` of `cloud`'s marching-slices mesh (request.method must be "slices", without
// anisotropic kernels). Throws std::invalid_argument when the grid has fewer blocks along its longest
// axis than `pieces`.
MeshPiece extract_mesh_piece(const ParticleCloud& cloud, const MeshSettings& request, int piece, int pieces);

// The pieces as one mesh, in piece order: vertices near the slabs' faces merged where position and normal
// are the same bits (the seams), every other vertex kept as it is.
TriangleMesh weld_mesh_pieces(std::span<const MeshPiece> pieces);

}  // namespace rivulet
