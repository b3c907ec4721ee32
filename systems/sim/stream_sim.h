#pragma once
// Ballistic stream simulation with a height-field pool (seed 000 §3): emitters, gravity, collisions
// against the ground, sphere and box colliders; particles that reach the pool push its surface and are
// absorbed. Deterministic at any thread count: emission draws counter-based random numbers keyed by
// (seed, frame, particle id); integrate() touches only its own particle range; pool impulses are applied
// in particle order in end_frame().
//
// One frame = begin_frame (serial) -> integrate over any split of [0, size) (parallel) -> end_frame (serial).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "systems/particles/aligned_array.h"
#include "systems/particles/particle_set.h"
#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"

namespace rivulet {

class HeightFieldPool;

class StreamSimulation {
public:
    // Preallocates everything for scene.max_particles; nothing allocates per frame afterwards.
    explicit StreamSimulation(const SceneDesc& scene);
    ~StreamSimulation();

    // Recycles particles older than the lifetime, emits this frame's new particles (appended at the end).
    void begin_frame(ParticleSet& particles, std::uint64_t frame);
    // Advances particles [begin, end) by one frame (scene.substeps substeps); records pool hits per particle.
    void integrate(ParticleSet& particles, std::size_t begin, std::size_t end);
    // Applies recorded pool hits in particle order, removes absorbed particles (stable), steps the pool.
    void end_frame(ParticleSet& particles);

    // Runs begin/integrate/end serially: for warm-up, tests and tools.
    void step_serial(ParticleSet& particles, std::uint64_t frame);

    HeightFieldView pool_view() const;
    const SceneDesc& scene() const { return scene_; }
    std::uint32_t next_id() const { return next_id_; }

private:
    SceneDesc scene_;
    std::uint32_t next_id_ = 0;
    double emit_carry_ = 0;  // fractional particles owed by the emitters
    AlignedArray<float> birth_time_;  // indexed by particle id % capacity? no: per slot, see .cpp
    AlignedArray<std::uint8_t> absorbed_;
    AlignedArray<float> hit_x_, hit_z_, hit_momentum_;
    std::vector<char> pool_storage_;  // owned pool, see HeightFieldPool
    HeightFieldPool* pool_ = nullptr;
    double time_ = 0;
};

}  // namespace rivulet
