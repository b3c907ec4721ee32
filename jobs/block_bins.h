#pragma once
// Particles into marching-slices blocks (Janisz §3.2.2): each particle is listed in every block whose
// corners it can influence (block plus a margin of R_c), stable (ascending particle index within a block),
// in chunks so the runtime can count and scatter in parallel. The prefix step is bin_prefix
// (jobs/bin_sort.h) with blocks as bins. When block_cubes >= 2 reach + 2 (reach = ceil(R_c / voxel): 10 at
// the defaults, against blocks of 40) a particle lands in at most 8 blocks; smaller blocks are allowed and
// simply list it in more.
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"

namespace rivulet {

// Corner range [lo, hi] per axis that particle (x, y, z) can influence (conservative), and the block
// range [blo, bhi] per axis whose corner ranges it touches.
struct ParticleReach {
    std::int32_t lo[3], hi[3];
    std::int32_t blo[3], bhi[3];
};
ParticleReach particle_reach(const SliceGrid& grid, float x, float y, float z);

// Blocks one particle can touch at most.
std::uint32_t max_blocks_per_particle(const SliceGrid& grid);

// Pass 1, per chunk: counts[b] = entries the chunk adds to block b (grid.blocks() slots).
void block_count_chunk(const SliceGrid& grid, ConstPositions p, std::span<std::uint32_t> counts);

struct BlockEntriesOut {
    std::span<std::uint32_t> entries;
    std::span<float> ex, ey, ez;
};

// Pass 2, per chunk: writes particle indices (first_index + i) and positions at the chunk's cursors.
void block_scatter_chunk(const SliceGrid& grid, ConstPositions p, std::uint32_t first_index,
                         std::span<std::uint32_t> cursors, const BlockEntriesOut& out);

}  // namespace rivulet
