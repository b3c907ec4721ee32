#pragma once
// The deterministic synthetic falling stream of the scan-conversion benchmarks (bench_scan_table.cpp
// describes it): P particles of radius kStreamRadius in ceil(P/1000) parallel streams (or `fixed_streams`),
// each a 1.5 m parabolic drop, slices one radius apart, each slice a jittered sunflower disk.
#include <cstddef>

#include "systems/particles/particle_set.h"

namespace rivulet::perf {

inline constexpr float kStreamRadius = 0.02f;

ParticleSet falling_stream(std::size_t particles, std::size_t fixed_streams = 0);

}  // namespace rivulet::perf
