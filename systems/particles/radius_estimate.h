#pragma once
#include "jobs/particle_spans.h"

namespace rivulet {

// A particle radius for files that come without one: half the median nearest-neighbour distance over a
// deterministic sample of up to 256 particles (brute force, O(256 N)). Returns 0 when there are fewer
// than two distinct positions.
float estimate_particle_radius(ConstPositions p);

}  // namespace rivulet
