#pragma once
// The producer of each frame's particles for a scene (DESIGN §1: simulation is a producer): it owns the
// ParticleSet and the scene's simulation, and adds the simulation's jobs to a frame graph. `run`,
// `simulate` and `replay` all drive the scene through this one class.
#include <cstdint>
#include <functional>
#include <memory>

#include "runtime/lib/frame_graph.h"
#include "systems/diffuse/diffuse_simulation.h"
#include "systems/particles/particle_set.h"
#include "systems/render/frame_view.h"
#include "systems/scenes/frame_inputs.h"
#include "systems/scenes/scene.h"
#include "systems/sim/sph_simulation.h"
#include "systems/sim/stream_sim.h"

namespace rivulet {

class SceneSimulation {
  public:
    using InputSource = std::function<FrameInputs(std::uint64_t frame)>;

    // Preallocates for scene.max_particles. `inputs` (empty: the scene's scripted inputs) is asked once
    // per simulated frame, warm-up included, on whichever thread runs the frame; it must not allocate.
    SceneSimulation(const SceneDesc& scene, InputSource inputs = {});
    ~SceneSimulation();

    // Adds the simulation's jobs after `after`: simulate.begin, the system's own jobs
    // (runtime/lib/simulation_jobs.h), simulate.end, which it returns. Each run of the graph simulates
    // frame next_frame() and then advances it.
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::initializer_list<FrameGraph::JobId> after = {});
    // The job of the last add_jobs after which the frame's input to its surface is final: a diffuse
    // object's sprites after its update (DiffuseSimulation::sprites), any other scene's particles at
    // simulate.end. A surface may run beside the rest of the frame from there.
    FrameGraph::JobId surface_input() const { return surface_input_; }
    // Simulates `frames` frames serially (warm-up; tools).
    void step_serial(int frames);

    const ParticleSet& particles() const { return particles_; }
    // The frame the next run simulates, and the one the last run simulated with its inputs.
    std::uint64_t next_frame() const { return next_frame_; }
    std::uint64_t last_frame() const { return last_frame_; }
    const FrameInputs& last_inputs() const { return last_inputs_; }
    HeightFieldView pool_view() const { return stream_ ? stream_->pool_view() : HeightFieldView{}; }
    // Diffuse scenes: the object (null otherwise).
    const DiffuseSimulation* diffuse() const { return diffuse_.get(); }
    // SPH scenes: the simulation (its last frame's solver figures); null otherwise.
    const SphSimulation* sph() const { return sph_.get(); }
    const SceneDesc& scene() const { return scene_; }

  private:
    void begin_frame();
    void end_frame();

    SceneDesc scene_;
    InputSource inputs_;
    ParticleSet particles_;
    std::unique_ptr<StreamSimulation> stream_;  // one of the two
    std::unique_ptr<SphSimulation> sph_;
    std::unique_ptr<DiffuseSimulation> diffuse_;
    std::uint64_t next_frame_ = 0, last_frame_ = 0;
    FrameGraph::JobId surface_input_ = 0;
    FrameInputs last_inputs_;
};

}  // namespace rivulet
