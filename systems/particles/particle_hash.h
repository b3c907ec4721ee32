#pragma once
// One 64-bit hash of a particle set's state (positions, velocities, ids, in array order): replay and
// determinism tests compare it frame by frame. Cheap enough to take every frame.
#include <cstdint>

#include "systems/particles/particle_set.h"

namespace rivulet {

std::uint64_t particle_hash(const ParticleSet& particles);

}  // namespace rivulet
