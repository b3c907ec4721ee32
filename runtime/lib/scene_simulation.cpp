#include "runtime/lib/scene_simulation.h"

#include "runtime/lib/simulation_jobs.h"
#include "systems/scenes/scene_validation.h"
#include "systems/sim/sph_scenes.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rivulet {

SceneSimulation::SceneSimulation(const SceneDesc& scene, InputSource inputs)
    : scene_(scene), inputs_(std::move(inputs)) {
    validate_scene(scene_);
    if (scene_.simulation == SimulationKind::kDiffuse) {
        diffuse_ = std::make_unique<DiffuseSimulation>(scene_, particles_);
        return;
    }
    if (scene_.simulation == SimulationKind::kStreams) {
        stream_ = std::make_unique<StreamSimulation>(scene_);
        particles_.reserve(scene_.max_particles);
        return;
    }
    sph_ = std::make_unique<SphSimulation>(sph_desc_of(scene_), scene_.max_particles);
    particles_.reserve(scene_.max_particles);
    sph_->seed(particles_);
}

SceneSimulation::~SceneSimulation() = default;

void SceneSimulation::begin_frame() {
    last_frame_ = next_frame_;
    last_inputs_ = inputs_ ? inputs_(last_frame_) : scripted_inputs(scene_, last_frame_);
    if (diffuse_) {
        diffuse_->begin_frame(particles_, last_frame_, last_inputs_.container_offset);
        return;
    }
    if (sph_) {
        sph_->set_container_offset(last_inputs_.container_offset);
        sph_->begin_frame(particles_, last_frame_);
        return;
    }
    stream_->set_inputs(last_inputs_);
    stream_->begin_frame(particles_, last_frame_);
}

void SceneSimulation::end_frame() {
    // A diffuse object's frame ends with its emission job; nothing is left to do here.
    if (sph_) {
        sph_->end_frame(particles_);
    } else if (stream_) {
        stream_->end_frame(particles_);
    }
    next_frame_ = last_frame_ + 1;
}

FrameGraph::JobId SceneSimulation::add_jobs(FrameGraph& graph,
                                            std::initializer_list<FrameGraph::JobId> after) {
    const auto begin = graph.serial(
        "simulate.begin", [this] { begin_frame(); }, after);
    const DiffuseJobs diffuse =
        diffuse_ ? add_diffuse_jobs(graph, *diffuse_, particles_, begin) : DiffuseJobs{};
    const FrameGraph::JobId body = diffuse_ ? diffuse.last
                                   : sph_   ? add_sph_jobs(graph, *sph_, particles_, begin)
                                            : add_stream_jobs(graph, *stream_, particles_, begin);
    const FrameGraph::JobId end = graph.serial("simulate.end", [this] { end_frame(); }, {body});
    surface_input_ = diffuse_ ? diffuse.sprites : end;
    return end;
}

void SceneSimulation::step_serial(int frames) {
    for (int i = 0; i < frames; ++i) {
        begin_frame();
        if (diffuse_) {
            diffuse_->run_phases_serial(particles_);
        } else if (sph_) {
            sph_->run_phases_serial(particles_);
        } else {
            stream_->integrate(particles_, 0, particles_.size());
        }
        end_frame();
    }
}

}  // namespace rivulet
