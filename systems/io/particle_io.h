#pragma once
// Particle position files in and out. Readers never return silently wrong data: anything malformed,
// truncated, non-finite or empty throws FileFormatError with the path and what is wrong.
#include <span>
#include <string>
#include <vector>

#include "systems/io/file_format_error.h"

namespace rivulet {

struct ParticleCloud {
    std::vector<float> x, y, z;  // SoA, like ParticleSet
    std::size_t size() const { return x.size(); }
};

// Dispatches on the extension, case-insensitively: .ply (ascii / binary little or big endian), .xyz
// (text columns), .vtk (legacy POLYDATA or UNSTRUCTURED_GRID, ascii or binary; only POINTS is read).
// At least one particle and only finite coordinates, else FileFormatError.
ParticleCloud read_particles(const std::string& path);

// Binary little-endian PLY with float x, y, z. The spans must have equal length (else FileFormatError);
// an empty cloud is written as a valid file, although read_particles rejects it.
void write_particles_ply(const std::string& path, std::span<const float> x, std::span<const float> y,
                         std::span<const float> z);

}  // namespace rivulet
