#include "systems/particles/particle_hash.h"

#include "jobs/mesh_hash.h"

namespace rivulet {

std::uint64_t particle_hash(const ParticleSet& p) {
    Hasher h;
    const std::uint64_t n = p.size();
    h.add(&n, sizeof n);
    h.add(p.x()), h.add(p.y()), h.add(p.z());
    h.add(p.vx()), h.add(p.vy()), h.add(p.vz());
    h.add(p.id());
    return h.digest();
}

}  // namespace rivulet
