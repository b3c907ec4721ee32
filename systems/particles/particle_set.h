#pragma once
// The particle store: structure of arrays (x, y, z, vx, vy, vz, stable id), each array 64-byte aligned,
// capacity preallocated. A particle's identity is its id, not its index (DESIGN §3.1).
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "jobs/particle_spans.h"
#include "systems/particles/aligned_array.h"

namespace rivulet {

class ParticleSet {
  public:
    ParticleSet() = default;
    explicit ParticleSet(std::size_t capacity) { reserve(capacity); }

    // Grows capacity (rare, allocates); live particles are kept.
    void reserve(std::size_t capacity);
    std::size_t capacity() const { return x_.capacity(); }
    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }

    // Live count changes never allocate; exceeding capacity throws std::length_error.
    void resize(std::size_t n) {
        if (n > capacity()) throw std::length_error("ParticleSet::resize beyond preallocated capacity");
        size_ = n;
    }
    void clear() { size_ = 0; }
    // Appends one particle; returns false (and adds nothing) when full.
    bool push(float x, float y, float z, float vx, float vy, float vz, std::uint32_t id) {
        if (size_ >= capacity()) return false;
        x_[size_] = x, y_[size_] = y, z_[size_] = z;
        vx_[size_] = vx, vy_[size_] = vy, vz_[size_] = vz;
        id_[size_] = id;
        ++size_;
        return true;
    }
    // Stable removal of every particle whose flag is non-zero (order of survivors kept).
    void remove_flagged(const std::uint8_t* dead);
    void copy_from(const ParticleSet& other);

    ParticleSpans spans() { return spans_over(size_); }
    // Spans over the first n places (n <= capacity), live or not: a compaction copies particles from
    // places past a count it has already lowered.
    ParticleSpans spans_over(std::size_t n) {
        if (n > capacity()) throw std::length_error("ParticleSet::spans_over beyond capacity");
        return {x_.span(n), y_.span(n), z_.span(n), vx_.span(n), vy_.span(n), vz_.span(n), id_.span(n)};
    }
    ConstPositions positions() const { return {x_.span(size_), y_.span(size_), z_.span(size_)}; }
    std::span<const float> x() const { return x_.span(size_); }
    std::span<const float> y() const { return y_.span(size_); }
    std::span<const float> z() const { return z_.span(size_); }
    std::span<const float> vx() const { return vx_.span(size_); }
    std::span<const float> vy() const { return vy_.span(size_); }
    std::span<const float> vz() const { return vz_.span(size_); }
    std::span<const std::uint32_t> id() const { return id_.span(size_); }

  private:
    AlignedArray<float> x_, y_, z_, vx_, vy_, vz_;
    AlignedArray<std::uint32_t> id_;
    std::size_t size_ = 0;
};

}  // namespace rivulet
