#pragma once
// The typical spacing of a particle set: the median, over a fixed sample of particles, of the distance
// from each to its nearest other particle. A regular fluid (a lattice, SPH output) has about the same
// nearest distance inside and on its surface, so the median is the spacing even when the sample holds
// many surface particles and a few droplets. Serial; the marching-slices spacing field runs it once.
//
// Particles are hashed into cells of edge `cell` (counting sort over a power-of-two table); a sample's
// nearest neighbour is searched in its 27 cells, so distances of `cell` or more all read as `cell`, and
// among at most 4096 entries (a sample with more around it is far denser than `cell`).
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"

namespace rivulet {

struct SpacingWorkspace {
    std::span<std::uint32_t> heads;  // nearest_spacing_table(n) + 1
    std::span<std::uint32_t> order;  // n
    std::span<float> nearest;        // samples
};

// Power-of-two hash table size for n particles (at least 2 n).
std::size_t nearest_spacing_table(std::size_t particles);

// The median nearest-neighbour distance of p, capped at `cell`, over min(samples, n) particles spread
// evenly through the index range. Requires n >= 1, cell > 0, samples >= 1, and every |coordinate -
// origin| / cell below 2^30 (the caller bounds the data's extent). One particle alone reads `cell`.
float nearest_spacing(ConstPositions p, const float origin[3], float cell, std::uint32_t samples,
                      SpacingWorkspace ws);

}  // namespace rivulet
