// rivulet simulate: run a scene's simulation only and write every frame's particles as a PLY sequence
// (DIR/frame_00000.ply, ...), which `rivulet mesh DIR/frame_{}.ply` or other tools read back.
#include <fmt/format.h>
#include <chrono>
#include <filesystem>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "runtime/lib/scene_simulation.h"
#include "runtime/lib/stage_summary.h"
#include "runtime/lib/thread_control.h"
#include "systems/io/particle_io.h"

namespace rivulet::cli {
namespace {

struct SimulateOptions {
    SceneOptions scene;
    int threads = 0;
    std::string out;
};

int simulate(const SimulateOptions& o) {
    SceneDesc scene = o.scene.resolve();
    ThreadControl threads(o.threads);
    std::filesystem::create_directories(o.out);

    SceneSimulation sim(scene);
    FrameGraph graph;
    sim.add_jobs(graph);
    sim.step_serial(scene.warmup_frames);
    std::vector<double> step_ms, write_ms;
    ProgressBar bar("frames", o.scene.frames);
    for (int i = 0; i < o.scene.frames; ++i) {
        graph.run();
        step_ms.push_back(graph.last_run_ms());
        const auto t0 = std::chrono::steady_clock::now();
        const ParticleSet& p = sim.particles();
        write_particles_ply(fmt::format("{}/frame_{:05d}.ply", o.out, i), p.x(), p.y(), p.z());
        write_ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        bar.update(i + 1);
    }
    fmt::print("scene {} | {} frames | {} threads | {} particles (last frame)\n", scene.name, o.scene.frames,
               threads.threads(), sim.particles().size());
    fmt::print("simulation {:.3f} ms/frame, PLY write {:.3f} ms/frame (medians)\n", median(step_ms),
               median(write_ms));
    fmt::print("particles: {}/frame_{{}}.ply (frames 00000 to {:05d})\n", o.out, o.scene.frames - 1);
    return 0;
}

}  // namespace

void add_simulate_command(CLI::App& app, int& status) {
    auto opts = std::make_shared<SimulateOptions>();
    CLI::App* cmd =
        app.add_subcommand("simulate", "Simulate a scene and write its particles as a PLY sequence");
    opts->scene.add_to(*cmd, "Frames to write");
    add_threads_option(*cmd, opts->threads, "Threads for TBB (0 = all)");
    cmd->add_option("--out", opts->out, "Directory for frame_00000.ply, frame_00001.ply, ...")->required();
    cmd->callback([opts, &status] { status = simulate(*opts); });
}

}  // namespace rivulet::cli
