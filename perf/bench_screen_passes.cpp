// Milliseconds of each pass of the screen-space fluid method (Janisz §3.1) on real frames: copy of the
// scene behind, sphere depth, depth smoothing, thickness (+ blur), composite. GL is finished after each
// pass, so the passes do not overlap; the frame's render time is measured in a second run without
// that, as users see it. Prints one row per scene and depth filter, medians over the frames.
//
//   bench_screen_passes [--threads 2] [--size 1280x720] [--frames 20] [--scenes fountain,dambreak]
//                       [--filters narrow-range,bilateral,curvature-flow] [--warmup N] [--max-taps K]
//                       [--filter-iterations N] [--filter-radius R] [--thickness-downsample D]
// One thread count per process: llvmpipe reads its thread count once.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/lib/allocator_tuning.h"
#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "systems/scenes/scene.h"

namespace {

using namespace rivulet;

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');)
        if (!item.empty()) out.push_back(item);
    return out;
}

struct Row {
    double copy = 0, depth = 0, smoothing = 0, thickness = 0, composite = 0, scene = 0, render = 0,
           particles = 0;
};

// One pipeline per scene, warmed up once; each filter swaps the renderer's screen pass in and runs
// `frames` frames timed pass by pass, then `frames` as users see them.
std::vector<Row> measure(const SceneDesc& scene, const std::vector<DepthSmoothing>& filters, int width,
                         int height, int frames, int max_taps, int iterations, float radius, int downsample) {
    PipelineSettings config;
    config.method = SurfaceMethod::kScreen;
    config.pipelined = false;  // the passes alone on the machine: extraction does not compete
    config.size = {width, height};
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    std::vector<Row> rows;
    const std::size_t skip = 3;
    for (DepthSmoothing filter : filters) {
        Row row;
        for (bool timed : {true, false}) {
            ScreenFluidSettings settings;
            settings.smoothing = filter;
            settings.filter_iterations = iterations > 0 ? iterations : default_filter_iterations(filter);
            if (radius > 0) settings.filter_radius = radius;
            if (downsample > 0) settings.thickness_downsample = downsample;
            settings.time_passes = timed;
            if (max_taps > 0) settings.max_filter_taps = max_taps;
            pipeline.renderer()->set_screen_fluid(settings);
            std::vector<double> copy, depth, smoothing, thickness, composite, rest, render, particles;
            pipeline.run(frames, [&](int i) {
                if (std::size_t(i) < skip) return;
                const ScreenFluidTimings& t = pipeline.renderer()->screen_fluid().timings();
                const FrameRecord& rec = pipeline.records().back();
                copy.push_back(t.copy_scene), depth.push_back(t.depth), smoothing.push_back(t.smoothing);
                thickness.push_back(t.thickness), composite.push_back(t.composite);
                // What the timed render spent outside the fluid's passes: sky, ground, shadows, glass.
                rest.push_back(rec.render_ms - t.copy_scene - t.depth - t.smoothing - t.thickness -
                               t.composite);
                render.push_back(rec.render_ms), particles.push_back(rec.particles);
            });
            if (timed) {
                row.copy = median(copy), row.depth = median(depth), row.smoothing = median(smoothing);
                row.thickness = median(thickness), row.composite = median(composite),
                row.scene = median(rest);
            } else {
                row.render = median(render), row.particles = median(particles);
            }
        }
        rows.push_back(row);
    }
    return rows;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Per-pass milliseconds of the screen-space fluid method"};
    int threads = 2, frames = 20, warmup = -1, max_taps = 0, iterations = 0, downsample = 0;
    float radius = 0;
    std::string size = "1280x720", scenes = "fountain,dambreak",
                filters = "narrow-range,bilateral,curvature-flow";
    app.add_option("--threads", threads)->check(CLI::Range(1, 256));
    app.add_option("--frames", frames)->check(CLI::Range(4, 10000));
    app.add_option("--size", size);
    app.add_option("--scenes", scenes);
    app.add_option("--filters", filters);
    app.add_option("--max-taps", max_taps, "Filter taps a side (default: the settings')")
        ->check(CLI::Range(0, 128));
    app.add_option("--filter-iterations", iterations, "Smoothing passes (default: the filter's)")
        ->check(CLI::Range(0, ScreenFluidSettings::kMaxIterations));
    app.add_option("--filter-radius", radius, "Smoothing width in particle radii (default: the settings')")
        ->check(CLI::Range(0.0f, 16.0f));
    app.add_option("--thickness-downsample", downsample,
                   "Thickness target's downsampling (default: the settings')")
        ->check(CLI::Range(0, 8));
    app.add_option("--warmup", warmup, "Warm-up frames (default: the scene's)")->check(CLI::Range(0, 100000));
    CLI11_PARSE(app, argc, argv);
    keep_freed_memory_for_reuse();  // as rivulet does: llvmpipe's per-frame buffers stay in the heap
    int width = 0, height = 0;
    if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2) {
        fmt::print(stderr, "bench_screen_passes: --size wants WxH, got {}\n", size);
        return 2;
    }
    ThreadControl control(threads);
    fmt::print("screen-space fluid passes, {}x{}, {} threads, medians of {} frames (ms)\n", width, height,
               threads, frames - 3);
    fmt::print("{:<10} {:<15} {:>9} {:>6} {:>6} {:>9} {:>9} {:>9} {:>16} {:>6} {:>10}\n", "scene", "filter",
               "particles", "copy", "depth", "smoothing", "thickness", "composite", "smooth+composite",
               "scene", "render");
    try {
        std::vector<DepthSmoothing> chosen;
        std::vector<std::string> names = split(filters);
        for (const std::string& f : names) {
            DepthSmoothing filter;
            if (!parse_depth_smoothing(f, filter)) {
                fmt::print(stderr, "bench_screen_passes: unknown filter {}\n", f);
                return 2;
            }
            chosen.push_back(filter);
        }
        for (const std::string& name : split(scenes)) {
            SceneDesc scene = make_builtin_scene(name);
            if (warmup >= 0) scene.warmup_frames = warmup;
            const std::vector<Row> rows =
                measure(scene, chosen, width, height, frames, max_taps, iterations, radius, downsample);
            for (std::size_t k = 0; k < rows.size(); ++k) {
                const Row& r = rows[k];
                fmt::print(
                    "{:<10} {:<15} {:>9.0f} {:>6.2f} {:>6.2f} {:>9.2f} {:>9.2f} {:>9.2f} {:>16.2f} {:>6.2f} "
                    "{:>10.2f}\n",
                    name, names[k], r.particles, r.copy, r.depth, r.smoothing, r.thickness, r.composite,
                    r.smoothing + r.composite, r.scene, r.render);
            }
        }
    } catch (const std::exception& e) {
        fmt::print(stderr, "bench_screen_passes: {}\n", e.what());
        return 1;
    }
    return 0;
}
