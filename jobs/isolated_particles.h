#pragma once
// Isolated particles (Hoetzlein & Höllerer 2009 §2.2): those whose circles joined no group. They are drawn as
// instanced low-resolution spheres instead of cylinders.
#include <cstdint>
#include <span>

#include "jobs/particle_spans.h"

namespace rivulet {

// Writes xyz of every particle with grouped[i] == 0, in particle order; returns how many.
std::uint32_t collect_isolated(ConstPositions particles, std::span<const std::uint8_t> grouped,
                               std::span<float> centers_xyz);

}  // namespace rivulet
