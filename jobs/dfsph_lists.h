#pragma once
// Neighbour lists of divergence-free SPH (Bender & Koschier 2015), built once per substep and read by
// every solver iteration: per sorted particle i, its neighbours j within h (itself excluded), each with
// V grad W_ij of the cubic spline as a vector (V is the rest volume): the iterations then read one
// neighbour value (its stiffness or its velocity) a pair instead of its position as well. In the same pass:
// the density ratio rho_i / rho0 = sum_j V W_ij + B_i, the wall's share B_i and its gradient, and the DFSPH
// factor
//   alpha_i = 1 / (|sum_j V grad W_ij + grad B_i|^2 + sum_j |V grad W_ij|^2)   (0 where that vanishes).
// The tank walls move with the tank and add their share B_i (DfsphWallTable) per face within h, faces at
// an edge or corner combined as if the kernel were separable; like boundary particles (Akinci et al.
// 2012) or volume maps (Bender et al. 2019) they count in the gradient sum only: the wall does not
// answer i's pressure. Lists live in per-chunk vectors that
// keep their capacity: in steady state nothing is allocated.
// The build: per cell, the particles of the 27 cells around it that lie within h of the box around the
// cell's own particles are copied into one run, which each of the cell's particles scans (eight at a
// time with AVX2 where the CPU has it, the hits compacted by a permute; four at a time in the baseline
// build); the hits' kernel values and gradients then go eight lanes at a time, each lane summing its
// share, the lanes added in a fixed tree at the end: the same bytes from either build at any thread
// count.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "jobs/sph_cubic_kernel.h"
#include "jobs/sph_density.h"

namespace rivulet {

// A pair holds the kernel's radial factor f, V grad W_ij = f (x_i - x_j): the passes make the vector
// from the packed positions (DfsphParticleOut::x4), which sit in the second-level cache, while the pairs
// stream from memory (24k particles: 11 MB of them a pass at 16 bytes, half that at 8). f (x_i - x_j)
// from the same floats is the build's own product, so the passes see the same vector to the bit.
struct DfsphPair {
    float f;
    std::uint32_t j;
};
static_assert(sizeof(DfsphPair) == 8, "a pair is two words");

// The wall's share of a particle's density at distance s from a wall plane: what a mirror image of the
// fluid would add if the fluid were the cubic lattice (spacing d) that the particle is a point of,
// B(s) = V sum_{k >= 0} sum_lateral W(|(lateral, 2 s + k d)|), tabulated over [0, h]. At s = d / 2 it
// completes a lattice's first layer to exactly rest density, and it rises twice as fast as the particle
// closes in (the image closes in too), so the wall holds the fluid off by its density alone: a
// continuous half-space (B = kernel mass beyond the plane) rises only as fast as the fluid's own share
// falls and lets the first layer drift onto the wall.
struct DfsphWallTable {
    static constexpr int kSamples = 256;
    float h = 1;
    std::array<float, kSamples + 1> mass{};
    DfsphWallTable() = default;
    DfsphWallTable(const SphCubicKernel& kernel, float volume, float d);
    // B by linear interpolation and A = -dB/ds as that interpolant's slope (0 from s = h on; s <= 0
    // reads s = 0).
    void at(float s, float& b, float& a) const;
};

// The particles of the cells around one cell, in cell-search order: each particle of that cell scans
// them as one run.
struct DfsphNearCells {
    std::vector<float> x, y, z;
    std::vector<std::uint32_t> j;
};
// One chunk's lists: particle i (of the chunk's range) has pairs [pair_begin[i], pair_end[i]) of the
// chunk's vector. Every list starts at a multiple of four pairs, and the pairs from its end to the next
// multiple are (0, i), i the particle itself: the passes read whole groups of four, one loop test per
// four pairs, and a pad pair's term is a zero, which leaves a sum's bits as they were. The vector keeps the
// size of the longest lists built so far; pairs past the last particle's pad are stale.
struct DfsphChunkLists {
    std::vector<DfsphPair> pairs;
    DfsphNearCells near;  // scratch of the build
};
struct DfsphParticleOut {
    std::span<std::uint32_t> pair_begin, pair_end;
    std::span<float> density_ratio, factor;
    std::span<float> wall_gx, wall_gy, wall_gz;  // grad B_i
    std::span<float> support;  // neighbours plus the wall's share (B_i times a full neighbourhood)
    std::span<float> x4;       // the positions packed (x, y, z, 0), which the passes read with the pairs
    // Optional, the divergence solve's warm start (jobs/dfsph_solve.h): with stiffness k_warm (every
    // particle's, set before the build) each particle's velocity gets dfsph_correct's correction, summed
    // in the build's lanes, and is written to vx, vy, vz and packed to v4 (x, y, z, 0): no pass of its own.
    std::span<const float> k_warm = {};
    std::span<float> vx = {}, vy = {}, vz = {}, v4 = {};
};

// Builds the lists of sorted particles [begin, end) into `lists` (from its start) and writes their
// per-particle values. `full_neighbours`: neighbours of a particle inside an unbounded lattice.
void dfsph_build_lists(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                       const SphWalls& walls, const DfsphWallTable& wall_table, float full_neighbours,
                       std::size_t begin, std::size_t end, DfsphChunkLists& lists,
                       const DfsphParticleOut& out);
// The x86-64 baseline build of dfsph_build_lists, which it runs where the CPU lacks AVX2 (or
// RIVULET_NO_AVX2 is set); tests compare the two builds byte for byte.
void dfsph_build_lists_baseline(const SphNeighbourhood& nb, const SphCubicKernel& kernel, float volume,
                                const SphWalls& walls, const DfsphWallTable& wall_table,
                                float full_neighbours, std::size_t begin, std::size_t end,
                                DfsphChunkLists& lists, const DfsphParticleOut& out);

// Rest volume of a particle such that the cubic spline density of an unbounded cubic lattice of spacing
// d is exactly 1 (so rho0 V is its mass).
float dfsph_lattice_volume(const SphCubicKernel& kernel, float d);
// Neighbours (within h, itself excluded) of a point inside an unbounded cubic lattice of spacing d.
int dfsph_lattice_neighbours(const SphCubicKernel& kernel, float d);

}  // namespace rivulet
