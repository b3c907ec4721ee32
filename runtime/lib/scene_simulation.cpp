#include "runtime/lib/scene_simulation.h"

#include <algorithm>

namespace rivulet {
namespace {

// Particles per integrate item: large enough to amortise scheduling, small enough to balance 8k.
constexpr std::size_t kSimChunk = 4096;

}  // namespace

SceneSimulation::SceneSimulation(const SceneDesc& scene, InputSource inputs)
    : scene_(scene), inputs_(std::move(inputs)) {
    stream_ = std::make_unique<StreamSimulation>(scene_);
    particles_.reserve(scene_.max_particles);
}

SceneSimulation::~SceneSimulation() = default;

void SceneSimulation::begin_frame() {
    last_frame_ = next_frame_;
    last_inputs_ = inputs_ ? inputs_(last_frame_) : scripted_inputs(scene_, last_frame_);
    stream_->set_inputs(last_inputs_);
    stream_->begin_frame(particles_, last_frame_);
}

void SceneSimulation::end_frame() {
    stream_->end_frame(particles_);
    next_frame_ = last_frame_ + 1;
}

FrameGraph::JobId SceneSimulation::add_jobs(FrameGraph& graph,
                                            std::initializer_list<FrameGraph::JobId> after) {
    const auto begin = graph.serial(
        "simulate.begin", [this] { begin_frame(); }, after);
    const auto integrate = graph.parallel(
        "simulate.integrate", [this] { return (particles_.size() + kSimChunk - 1) / kSimChunk; },
        [this](std::size_t c) {
            const std::size_t b = c * kSimChunk;
            stream_->integrate(particles_, b, std::min(particles_.size(), b + kSimChunk));
        },
        {begin});
    return graph.serial("simulate.end", [this] { end_frame(); }, {integrate});
}

void SceneSimulation::step_serial(int frames) {
    for (int i = 0; i < frames; ++i) {
        begin_frame();
        stream_->integrate(particles_, 0, particles_.size());
        end_frame();
    }
}

}  // namespace rivulet
