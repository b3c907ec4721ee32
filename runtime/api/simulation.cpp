#include "rivulet/simulation.h"

#include "runtime/api/api_support.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/scene_simulation.h"
#include "systems/scenes/scene.h"
#include "systems/scenes/scene_json.h"
#include "systems/scenes/scene_validation.h"

namespace rivulet {

struct Simulation::State {
    SceneDesc scene;
    api::WorkerArena arena;
    int threads = 0;
    std::unique_ptr<SceneSimulation> sim;
    std::unique_ptr<FrameGraph> graph;
    std::uint64_t frames = 0;
};

Simulation::Simulation(const std::string& scene, int warmup, int threads)
    : state_(std::make_unique<State>()) {
    api::translate_errors([&] {
        State& s = *state_;
        s.scene = resolve_scene(scene);
        if (warmup != -1) s.scene.warmup_frames = warmup;  // validate_scene bounds it as a scene file's
        validate_scene(s.scene);
        s.threads = threads;
        tbb::task_arena& workers = s.arena.get(threads);
        s.sim = std::make_unique<SceneSimulation>(s.scene);
        s.graph = std::make_unique<FrameGraph>();
        s.sim->add_jobs(*s.graph);
        workers.execute([&] { s.sim->step_serial(s.scene.warmup_frames); });
    });
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

void Simulation::step() {
    api::translate_errors([&] {
        State& s = *state_;
        s.arena.get(s.threads).execute([&] { s.graph->run(); });
        ++s.frames;
    });
}

PositionsView Simulation::positions() const {
    const ConstPositions p = state_->sim->particles().positions();
    return {p.x, p.y, p.z};
}

std::uint64_t Simulation::frame() const {
    return state_->frames;
}
const std::string& Simulation::name() const {
    return state_->scene.name;
}
float Simulation::particle_radius() const {
    return state_->scene.particle_radius;
}
float Simulation::frame_rate() const {
    return 1.0f / state_->scene.dt;
}
std::size_t Simulation::max_particles() const {
    return state_->scene.max_particles;
}

std::vector<std::string> Simulation::builtin_scenes() {
    std::vector<std::string> names;
    for (std::string_view n : builtin_scene_names()) names.emplace_back(n);
    return names;
}

}  // namespace rivulet
