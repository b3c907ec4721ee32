#include "systems/io/particle_io.h"

#include <cmath>

#include "systems/io/particle_readers.h"
#include "systems/io/text_parse.h"

namespace rivulet {

namespace io {

void validate_particles(const std::string& path, const ParticleCloud& cloud) {
    if (cloud.x.empty()) throw FileFormatError(path + ": no particles");
    for (std::size_t i = 0; i < cloud.x.size(); ++i) {
        if (!std::isfinite(cloud.x[i]) || !std::isfinite(cloud.y[i]) || !std::isfinite(cloud.z[i])) {
            throw FileFormatError(path + ": non-finite coordinate at particle " + std::to_string(i) +
                                  " (x=" + std::to_string(cloud.x[i]) + ", y=" + std::to_string(cloud.y[i]) +
                                  ", z=" + std::to_string(cloud.z[i]) + ")");
        }
    }
}

}  // namespace io

ParticleCloud read_particles(const std::string& path) {
    const std::string ext = io::lower_extension(path);
    ParticleCloud cloud;
    if (ext == ".ply") {
        cloud = io::read_ply_particles(path);
    } else if (ext == ".xyz") {
        cloud = io::read_xyz_particles(path);
    } else if (ext == ".vtk") {
        cloud = io::read_vtk_particles(path);
    } else {
        throw FileFormatError(path + ": unknown particle file extension " + io::quoted(ext) +
                              " (expected .ply, .xyz or .vtk)");
    }
    io::validate_particles(path, cloud);
    return cloud;
}

}  // namespace rivulet
