#pragma once
// The spacing of a particle set as the marching-slices spacing field needs it: the edge of the cubic
// lattice with the same number density, d = n^(-1/3). Nearest-neighbour distances alone mislead: a
// relaxed SPH fluid sits irregularly, its nearest neighbours about 0.8 d apart at the lattice's density.
//
//   1. d0: the median, over a fixed sample of particles, of the distance to the nearest other particle
//      (capped at `cap`: sparser data read as `cap`).
//   2. n per sample: the SPH number density, a sum of the cubic spline kernel (jobs/sph_cubic_kernel.h)
//      with support 3 d0 over the sample's neighbours (itself included): on lattices the spacing it gives
//      is within 1 %, on an irregular fluid a few percent short (its local density fluctuations).
//   3. d = n^(-1/3) at the 80th percentile of n: interior particles, whose kernels are full (a surface
//      particle's is about half empty), as long as a fifth of the sample is interior.
//
// Particles are hashed into cells (jobs/cell_hash.h), a sample searched in its 27 cells with at most 4096
// entries (more means a pile far denser than any cell, e.g. coincident
// particles, whose spacing reads as about 0). Serial; the slices extractor runs it once.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/cell_hash.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct SpacingWorkspace {
    std::span<std::uint32_t> heads;  // cell_hash_table_size(n) + 1 (jobs/cell_hash.h)
    std::span<std::uint32_t> order;  // n
    std::span<float> values;         // samples
};

// The spacing above, at most `cap`, over min(samples, n) particles spread evenly through the index range.
// Requires n >= 1, cap > 0, samples >= 1, and every |coordinate - origin| / (cap / 4) below 2^30 (the
// caller bounds the data's extent). One particle alone reads `cap`.
float particle_spacing(ConstPositions p, const float origin[3], float cap, std::uint32_t samples,
                       SpacingWorkspace ws);

}  // namespace rivulet
