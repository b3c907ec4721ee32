// Diffuse objects (Juckel & Beckhaus, "Rendering diffuse objects using particle systems inside voxelized
// surface geometry"): milliseconds of a frame's CPU side, the particles' update (forces, collisions,
// voxel lookup, fading, emission), the back-to-front radix sort and the staging of the sprites, for a
// given particle count at a given thread count; then the render thread's milliseconds for those sprites.
// The object is the scene's mesh with max_density raised until its voxels hold the count, so every frame
// updates, sorts and stages that many particles. Prints one row per count, medians over the frames.
//
//   bench_diffuse [--scene ghost] [--particles 40000,250000,1000000] [--threads 2] [--frames 30]
//                 [--size 1280x720] [--no-render] [--jobs]
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <string>
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
SceneDesc sized(SceneDesc scene, std::uint32_t particles) {
    ParticleSet probe;
    scene.max_particles = 1;
    const DiffuseSimulation sim(scene, probe);
    const double inside = double(sim.object().inside.size());
    scene.max_particles = particles;
    scene.diffuse.defaults.max_density = float(std::ceil(1.15 * particles / inside));
    for (DiffuseRegion& r : scene.diffuse.regions)
        r.attributes.max_density = scene.diffuse.defaults.max_density;
    scene.diffuse.defaults.fill_time = 0.2f;
    scene.warmup_frames = 40;
    return scene;
}

double stage(const FramePipeline& p, const char* prefix, std::size_t skip) {
    std::vector<double> v;
    const auto& recs = p.records();
    for (std::size_t i = skip; i < recs.size(); ++i) {
        double sum = 0;
        for (FrameGraph::JobId j = 0; j < p.graph().job_count(); ++j)
            if (p.graph().job_name(j).rfind(prefix, 0) == 0) sum += recs[i].job_ms[j];
        v.push_back(sum);
    }
    return median(v);
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
    CLI11_PARSE(app, argc, argv);
    keep_freed_memory_for_reuse();
    ThreadControl control(threads);
    int width = 1280, height = 720;
    if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2) return 2;

    fmt::print("scene {}, {} threads, {} frames per row, {}x{}; medians in ms\n", scene_name, threads, frames,
               width, height);
    fmt::print("{:>9} {:>9} {:>8} {:>8} {:>8} {:>8} {:>8} {:>9} {:>9}\n", "particles", "live", "update",
               "compact", "emit", "sort", "stage", "cpu_total", "render");
    for (const std::string& c : bench::split_list(counts)) {
        const SceneDesc scene = sized(resolve_scene(scene_name), static_cast<std::uint32_t>(std::stoul(c)));
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
        fmt::print("{:>9} {:>9.0f} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>9.2f} {:>9.2f}\n", c,
                   median(live), stage(pipeline, "diffuse.update", skip),
                   stage(pipeline, "diffuse.compact", skip), stage(pipeline, "diffuse.emit", skip),
                   stage(pipeline, "sprites.keys", skip) + stage(pipeline, "sprites.histogram", skip) +
                       stage(pipeline, "sprites.prefix", skip) + stage(pipeline, "sprites.scatter", skip),
                   stage(pipeline, "sprites.stage", skip), median(total), no_render ? 0.0 : median(render));
        if (jobs)
            for (FrameGraph::JobId j = 0; j < pipeline.graph().job_count(); ++j)
                fmt::print("    {:<28} {:>8.3f}\n", pipeline.graph().job_name(j),
                           stage(pipeline, std::string(pipeline.graph().job_name(j)).c_str(), skip));
        std::fflush(stdout);
    }
}
