#pragma once
// Per-format particle readers behind read_particles. They only parse; read_particles applies the checks
// every format shares (non-empty, finite).
#include <string>

#include "systems/io/coordinate.h"
#include "systems/io/particle_io.h"

namespace rivulet::io {

ParticleCloud read_ply_particles(const std::string& path);
ParticleCloud read_xyz_particles(const std::string& path);
ParticleCloud read_vtk_particles(const std::string& path);

// Throws if the cloud is empty or holds a non-finite coordinate (naming the first bad particle).
void validate_particles(const std::string& path, const ParticleCloud& cloud);

}  // namespace rivulet::io
