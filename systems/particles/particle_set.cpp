#include "systems/particles/particle_set.h"

#include <cstring>

namespace rivulet {

void ParticleSet::reserve(std::size_t capacity) {
    x_.reserve(capacity, size_), y_.reserve(capacity, size_), z_.reserve(capacity, size_);
    vx_.reserve(capacity, size_), vy_.reserve(capacity, size_), vz_.reserve(capacity, size_);
    id_.reserve(capacity, size_);
}

void ParticleSet::remove_flagged(const std::uint8_t* dead) {
    std::size_t w = 0;
    for (std::size_t r = 0; r < size_; ++r) {
        if (dead[r]) continue;
        if (w != r) {
            x_[w] = x_[r], y_[w] = y_[r], z_[w] = z_[r];
            vx_[w] = vx_[r], vy_[w] = vy_[r], vz_[w] = vz_[r];
            id_[w] = id_[r];
        }
        ++w;
    }
    size_ = w;
}

void ParticleSet::copy_from(const ParticleSet& other) {
    if (other.size_ > capacity()) reserve(other.size_);
    const std::size_t n = other.size_;
    size_ = n;
    if (n == 0) return;
    std::memcpy(x_.data(), other.x_.data(), n * sizeof(float));
    std::memcpy(y_.data(), other.y_.data(), n * sizeof(float));
    std::memcpy(z_.data(), other.z_.data(), n * sizeof(float));
    std::memcpy(vx_.data(), other.vx_.data(), n * sizeof(float));
    std::memcpy(vy_.data(), other.vy_.data(), n * sizeof(float));
    std::memcpy(vz_.data(), other.vz_.data(), n * sizeof(float));
    std::memcpy(id_.data(), other.id_.data(), n * sizeof(std::uint32_t));
}

}  // namespace rivulet
