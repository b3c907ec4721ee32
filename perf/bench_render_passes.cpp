// Milliseconds of each part of the render thread's frame, per surface method, on real frames: upload,
// shadow map, the scene (ground, solids, sky, back glass), the mesh methods' water thickness (with the
// scene copy) and lit water, the screen-space pass, and the finish. GL is finished after each part so
// parts do not overlap; a second run without that gives the render time users see, and the frame graph's
// time (simulation + extraction) of the same frames. Prints one row per scene and method, medians.
//
//   bench_render_passes [--threads 2] [--size 1280x720] [--frames 10] [--scenes fountain,dambreak]
//                       [--methods scan,slices,screen] [--warmup N]
// One thread count per process: llvmpipe reads its thread count once.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

#include "perf/support/bench_util.h"
#include "runtime/lib/allocator_tuning.h"
#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "systems/render/renderer.h"
#include "systems/scenes/scene.h"

namespace {

using namespace rivulet;
using bench::median;

struct Row {
    RenderTimings parts;
    double render = 0, extract = 0, particles = 0, triangles = 0;
};

Row measure(const SceneDesc& scene, SurfaceMethod method, int width, int height, int frames) {
    PipelineSettings config;
    config.method = method;
    config.pipelined = false;  // the render thread's parts alone on the machine
    config.size = {width, height};
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    const std::size_t skip = 2;
    Row row;
    for (bool timed : {true, false}) {
        pipeline.renderer()->set_time_passes(timed);
        std::vector<double> upload, shadow, scene_ms, thickness, water, screen, finish, render, extract,
            particles, triangles;
        pipeline.run(frames, [&](int i) {
            if (std::size_t(i) < skip) return;
            const RenderTimings& t = pipeline.renderer()->timings();
            const FrameRecord& rec = pipeline.records().back();
            if (timed) {
                upload.push_back(t.upload), shadow.push_back(t.shadow), scene_ms.push_back(t.scene);
                thickness.push_back(t.water_thickness), water.push_back(t.water);
                screen.push_back(t.screen), finish.push_back(t.finish);
            } else {
                render.push_back(rec.render_ms), extract.push_back(rec.extract_ms);
                particles.push_back(rec.particles), triangles.push_back(double(rec.triangles));
            }
        });
        if (timed) {
            row.parts = {median(upload), median(shadow), median(scene_ms), median(thickness),
                         median(water),  median(screen), median(finish)};
        } else {
            row.render = median(render), row.extract = median(extract);
            row.particles = median(particles), row.triangles = median(triangles);
        }
    }
    return row;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Per-part milliseconds of the render thread, per surface method"};
    int threads = 2, frames = 10, warmup = -1;
    std::string size = "1280x720", scenes = "fountain,dambreak", methods = "scan,slices,screen";
    app.add_option("--threads", threads)->check(CLI::Range(1, 256));
    app.add_option("--frames", frames)->check(CLI::Range(3, 10000));
    app.add_option("--size", size);
    app.add_option("--scenes", scenes);
    app.add_option("--methods", methods);
    app.add_option("--warmup", warmup, "Warm-up frames (default: the scene's)")->check(CLI::Range(0, 100000));
    CLI11_PARSE(app, argc, argv);
    keep_freed_memory_for_reuse();  // as rivulet does: llvmpipe's per-frame buffers stay in the heap
    int width = 0, height = 0;
    if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2) {
        fmt::print(stderr, "bench_render_passes: --size wants WxH, got {}\n", size);
        return 2;
    }
    ThreadControl control(threads);
    fmt::print("render passes, {}x{}, {} threads, medians of {} frames (ms)\n", width, height, threads,
               frames - 2);
    fmt::print("{:<10} {:<7} {:>9} {:>9} {:>7} {:>7} {:>7} {:>10} {:>7} {:>7} {:>7} {:>8} {:>8}\n", "scene",
               "method", "particles", "triangles", "upload", "shadow", "scene", "thickness", "water",
               "screen", "finish", "render", "extract");
    try {
        for (const std::string& name : bench::split_list(scenes)) {
            SceneDesc scene = make_builtin_scene(name);
            if (warmup >= 0) scene.warmup_frames = warmup;
            for (const std::string& m : bench::split_list(methods)) {
                const Row r = measure(scene, parse_surface_method(m), width, height, frames);
                const RenderTimings& p = r.parts;
                fmt::print(
                    "{:<10} {:<7} {:>9.0f} {:>9.0f} {:>7.2f} {:>7.2f} {:>7.2f} {:>10.2f} {:>7.2f} {:>7.2f} "
                    "{:>7.2f} {:>8.2f} {:>8.2f}\n",
                    name, m, r.particles, r.triangles, p.upload, p.shadow, p.scene, p.water_thickness,
                    p.water, p.screen, p.finish, r.render, r.extract);
                std::fflush(stdout);
            }
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_render_passes: {}\n", e.what());
        return 1;
    }
    return 0;
}
