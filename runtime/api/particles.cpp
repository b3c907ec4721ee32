#include "rivulet/particles.h"

#include "runtime/api/api_support.h"
#include "systems/io/particle_io.h"

namespace rivulet {

Particles load_particles(const std::string& path) {
    return api::translate_errors([&] {
        const ParticleCloud cloud = read_particles(path);
        Particles out;
        out.xyz.resize(3 * cloud.size());
        for (std::size_t i = 0; i < cloud.size(); ++i)
            out.xyz[3 * i] = cloud.x[i], out.xyz[3 * i + 1] = cloud.y[i], out.xyz[3 * i + 2] = cloud.z[i];
        return out;
    });
}

void save_particles(const std::string& path, std::span<const float> xyz) {
    api::translate_errors([&] {
        if (xyz.size() % 3 != 0)
            throw Error(path + ": " + std::to_string(xyz.size()) + " floats is not 3 a particle");
        const std::size_t n = xyz.size() / 3;
        std::vector<float> x(n), y(n), z(n);
        for (std::size_t i = 0; i < n; ++i) x[i] = xyz[3 * i], y[i] = xyz[3 * i + 1], z[i] = xyz[3 * i + 2];
        write_particles_ply(path, x, y, z);
    });
}

}  // namespace rivulet
