#pragma once
// A block's triangle corners to mesh vertex indices (marching slices' weld): the block numbers the
// vertices it owns 0, 1, ... and those other blocks own from its capacity down, so owned vertex v is mesh
// vertex offset + v and any other is looked up, as slot top - v of the block's foreign list.
#include <cstdint>
#include <span>

namespace rivulet {

struct BlockVertexMap {
    std::uint32_t owned = 0;                 // block vertices below this are the block's own
    std::uint32_t offset = 0;                // mesh index of owned vertex 0
    std::uint32_t top = 0;                   // foreign vertex v is foreign[top - v]
    std::span<const std::uint32_t> foreign;  // mesh index of each foreign vertex
};

// out[t] = the mesh index of block vertex local[t]; out.size() == local.size().
void weld_indices(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                  std::span<std::uint32_t> out);
// The x86-64 baseline build, which weld_indices runs where the CPU lacks AVX2; tests compare the two.
void weld_indices_baseline(std::span<const std::uint32_t> local, const BlockVertexMap& map,
                           std::span<std::uint32_t> out);

}  // namespace rivulet
