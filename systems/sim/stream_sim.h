#pragma once
// Ballistic stream simulation with a height-field pool (Hoetzlein & Höllerer 2009 §3): emitters, gravity,
// collisions against the ground, sphere and box colliders; particles that reach the pool push its surface and
// are absorbed. Deterministic at any thread count: emission draws counter-based random numbers keyed by
// (seed, frame, particle id); integrate() touches only its own particle range; pool impulses are applied
// in particle order in end_frame().
//
// One frame = begin_frame (serial) -> integrate over any split of [0, size) (parallel) -> end_frame (serial).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "jobs/ballistic_step.h"
#include "systems/particles/aligned_array.h"
#include "systems/particles/particle_set.h"
#include "systems/render/frame_view.h"
#include "systems/scenes/frame_inputs.h"
#include "systems/scenes/scene.h"

namespace rivulet {

class HeightFieldPool;

class StreamSimulation {
  public:
    // Preallocates everything for scene.max_particles; nothing allocates per frame afterwards.
    explicit StreamSimulation(const SceneDesc& scene);
    ~StreamSimulation();

    // Emits this frame's new particles (appended at the end; none once the set or max_particles is full).
    void begin_frame(ParticleSet& particles, std::uint64_t frame);
    // Advances particles [begin, end) by one frame (scene.substeps substeps); records pool hits per particle.
    void integrate(ParticleSet& particles, std::size_t begin, std::size_t end);
    // Applies recorded pool hits in particle order, removes absorbed and recycled particles (stable: too
    // old, resting on the ground, or lost) and steps the pool. Every index must have been integrated.
    void end_frame(ParticleSet& particles);

    // Runs begin/integrate/end serially: for warm-up, tests and tools.
    void step_serial(ParticleSet& particles, std::uint64_t frame);

    // This frame's outside inputs (emitter_scale multiplies every emitter's rate); set before begin_frame.
    void set_inputs(const FrameInputs& inputs);

    HeightFieldView pool_view() const;
    const SceneDesc& scene() const { return scene_; }
    std::uint32_t next_id() const { return next_id_; }

  private:
    // Orthonormal frame of an emitter's direction, for the cone and nozzle-disk jitter.
    struct EmitterFrame {
        Vec3f axis, side, up;
    };

    SceneDesc scene_;
    std::uint32_t next_id_ = 0;
    std::uint32_t tick_ = 0;     // frames completed; birth stamps are taken from it
    std::size_t stamped_ = 0;    // leading particles whose birth stamp is known
    std::vector<double> carry_;  // per emitter: fraction of a particle owed from earlier frames
    std::vector<EmitterFrame> frames_;
    std::vector<SphereObstacle> spheres_;
    std::vector<BoxObstacle> boxes_;
    // Per particle index, compacted with the ParticleSet in end_frame.
    AlignedArray<std::uint32_t> birth_;
    AlignedArray<std::uint8_t> fate_;
    AlignedArray<float> hit_x_, hit_z_, hit_momentum_;
    std::unique_ptr<HeightFieldPool> pool_;  // null when the scene has no pool
    BallisticParams params_;
    float emitter_scale_ = 1;
};

}  // namespace rivulet
