#pragma once
// Particle files in and out: PLY (ASCII, binary little or big endian), XYZ text columns and legacy VTK
// (POLYDATA or UNSTRUCTURED_GRID), chosen by extension, as `rivulet mesh` reads them. Malformed,
// truncated, oversized (text formats: docs/limits.md) or non-finite files throw rivulet::Error
// naming the file and what is wrong.
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace rivulet {

struct Particles {
    std::vector<float> xyz;  // 3 floats a particle, interleaved
    std::size_t size() const { return xyz.size() / 3; }
};

Particles load_particles(const std::string& path);
// Binary little-endian PLY with float x, y, z (3 floats a particle, interleaved).
void save_particles(const std::string& path, std::span<const float> xyz);

}  // namespace rivulet
