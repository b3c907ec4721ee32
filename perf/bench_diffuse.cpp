// Diffuse objects (Juckel & Beckhaus, "Rendering diffuse objects using particle systems inside voxelized
// surface geometry"): milliseconds of a frame's CPU side, the particles' update (forces, collisions,
// voxel lookup, fading, the sort keys), the compaction, the emission and the back-to-front radix sort
// (the sprites themselves are handed over where the update wrote them), for a given particle count at a
// given thread count; then the render thread's milliseconds for those sprites. The object is the scene's
// mesh with max_density raised until its voxels hold the count, so every frame updates and sorts that
// many particles. Prints one row per count, medians over the frames.
//
//   bench_diffuse [--scene ghost] [--particles 40000,250000,1000000] [--threads 2] [--frames 30]
//                 [--warmup 40] [--size 1280x720] [--no-render] [--jobs]
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "perf/support/bench_util.h"
#include "runtime/lib/allocator_tuning.h"
#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "systems/scenes/scene_json.h"

namespace {

using namespace rivulet;
using bench::median;

// The scene with room for `particles` and voxels dense enough to hold them all.
SceneDesc sized(SceneDesc scene, std::uint32_t particles, int warmup) {
    ParticleSet probe;
    scene.max_particles = 1;
    const DiffuseSimulation sim(scene, probe);
    const double inside = double(sim.object().inside.size());
    scene.max_particles = particles;
    scene.diffuse.defaults.max_density = float(std::ceil(1.15 * particles / inside));
    for (DiffuseRegion& r : scene.diffuse.regions)
        r.attributes.max_density = scene.diffuse.defaults.max_density;
    scene.diffuse.defaults.fill_time = 0.2f;
    scene.warmup_frames = warmup;
    return scene;
}

// Median over the frames after `skip` of the summed ms of the jobs `pick(name)` selects.
template <class Pick>
double jobs_ms(const FramePipeline& p, std::size_t skip, Pick&& pick) {
    std::vector<double> v;
    const auto& recs = p.records();
    for (std::size_t i = skip; i < recs.size(); ++i) {
        double sum = 0;
        for (FrameGraph::JobId j = 0; j < p.graph().job_count(); ++j)
            if (pick(std::string_view(p.graph().job_name(j)))) sum += recs[i].job_ms[j];
        v.push_back(sum);
    }
    return median(v);
}

double prefixed(const FramePipeline& p, std::string_view prefix, std::size_t skip) {
    return jobs_ms(p, skip, [&](std::string_view name) { return name.substr(0, prefix.size()) == prefix; });
}

void run_rows(const std::string& scene_name, const std::string& counts, int warmup, int frames,
              bool no_render, bool jobs, int width, int height) {
    for (const std::string& c : bench::split_list(counts)) {
        const SceneDesc scene =
            sized(resolve_scene(scene_name), static_cast<std::uint32_t>(std::stoul(c)), warmup);
        PipelineSettings config;
        config.method = SurfaceMethod::kSprites;
        config.render = !no_render;
        config.pipelined = false;  // the CPU side alone on the machine, then the render alone
        config.size = {width, height};
        FramePipeline pipeline(scene, config);
        pipeline.warmup();
        pipeline.run(frames + 2);
        const std::size_t skip = 2;
        std::vector<double> total, render, live;
        for (std::size_t i = skip; i < pipeline.records().size(); ++i) {
            total.push_back(pipeline.records()[i].extract_ms);
            render.push_back(pipeline.records()[i].render_ms);
            live.push_back(pipeline.records()[i].particles);
        }
        fmt::print("{:>9} {:>9.0f} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>9.2f} {:>9.2f}\n", c, median(live),
                   prefixed(pipeline, "diffuse.update", skip), prefixed(pipeline, "diffuse.compact", skip),
                   prefixed(pipeline, "diffuse.emit", skip), prefixed(pipeline, "sprites.", skip),
                   median(total), no_render ? 0.0 : median(render));
        if (jobs)
            for (FrameGraph::JobId j = 0; j < pipeline.graph().job_count(); ++j) {
                const std::string_view name = pipeline.graph().job_name(j);
                fmt::print("    {:<28} {:>8.3f}\n", name,
                           jobs_ms(pipeline, skip, [&](std::string_view n) { return n == name; }));
            }
        std::fflush(stdout);
    }
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Diffuse objects: update + sort + staging ms, and render ms, per particle count"};
    std::string scene_name = "ghost", counts = "40000,250000,1000000", size = "1280x720";
    int threads = 2, frames = 30;
    bool no_render = false;
    app.add_option("--scene", scene_name, "Diffuse scene, built-in or FILE.json")->capture_default_str();
    app.add_option("--particles", counts, "Comma-separated particle counts")->capture_default_str();
    app.add_option("--threads", threads, "Worker threads")->capture_default_str();
    app.add_option("--frames", frames, "Timed frames per count")->capture_default_str();
    app.add_option("--size", size, "Picture size WxH")->capture_default_str();
    app.add_flag("--no-render", no_render, "CPU side only");
    bool jobs = false;
    app.add_flag("--jobs", jobs, "Also print every job's median ms");
    int warmup = 40;
    app.add_option("--warmup", warmup,
                   "Simulated frames before the timed ones (the ghost's ball crosses it "
                   "at about 120)")
        ->check(CLI::Range(1, 100000))
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);
    keep_freed_memory_for_reuse();
    ThreadControl control(threads);
    int width = 1280, height = 720;
    if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2) return 2;

    fmt::print("scene {}, {} threads, {} frames per row, {}x{}; medians in ms\n", scene_name, threads, frames,
               width, height);
    fmt::print("{:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9}\n", "particles", "live", "update", "compact",
               "emit", "sort", "cpu_total", "render");
    try {
        run_rows(scene_name, counts, warmup, frames, no_render, jobs, width, height);
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_diffuse: {}\n", e.what());
        return 1;
    }
}
