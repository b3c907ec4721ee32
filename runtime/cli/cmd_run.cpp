// rivulet run: simulate a scene, extract its surface and render it, frame after frame, pipelined.
#include <fmt/format.h>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <span>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/recording.h"
#include "runtime/lib/stage_summary.h"
#include "runtime/lib/thread_control.h"
#include "runtime/lib/trace_recorder.h"
#include "runtime/lib/trace_summary.h"
#include "systems/io/output_file.h"
#include "systems/render/video_writer.h"
#include "systems/scenes/input_track.h"
#include "systems/scenes/scene_limits.h"

namespace rivulet::cli {
namespace {

struct RunOptions {
    SceneOptions scene;
    std::string method;  // empty: scan, or sprites for a diffuse scene
    int threads = 0;
    std::string out = "out";
    std::string video;
    std::string size = "1280x720";
    std::string json;
    std::string trace;
    std::string graph;  // the frame graph as Graphviz DOT
    std::string record;
    std::string inputs;  // an input track (systems/scenes/input_track.h); empty: the scene's script
    int timing_warmup = 0;
    bool no_pipeline = false;
    bool no_render = false;
    ScanOptions scan;
    SlicesOptions slices;
    ScreenOptions screen;
    VolumeOptions volume;
};

// Medians over the frames after the first `skip` (caches, allocator and llvmpipe settling).
StageSummary summarize(const FramePipeline& p, int skip) {
    StageSummary s;
    const auto& all = p.records();
    const std::span<const FrameRecord> recs =
        std::span(all).subspan(std::min(all.size(), static_cast<std::size_t>(skip)));
    s.frames = static_cast<int>(recs.size());
    auto column = [&](auto get) {
        std::vector<double> v;
        for (const FrameRecord& r : recs) v.push_back(get(r));
        return median(std::move(v));
    };
    for (FrameGraph::JobId j = 0; j < p.graph().job_count(); ++j)
        s.stage_ms.emplace_back(p.graph().job_name(j),
                                column([j](const FrameRecord& r) { return r.job_ms[j]; }));
    s.frame_ms = column([](const FrameRecord& r) { return r.frame_ms; });
    s.render_ms = column([](const FrameRecord& r) { return r.render_ms; });
    s.extract_ms = column([](const FrameRecord& r) { return r.extract_ms; });
    s.frames_per_second = s.frame_ms > 0 ? 1000.0 / s.frame_ms : 0;
    return s;
}

int run(const RunOptions& o) {
    if (o.timing_warmup >= o.scene.frames)
        throw std::invalid_argument(fmt::format("--timing-warmup ({}) must be less than --frames ({})",
                                                o.timing_warmup, o.scene.frames));
    SceneDesc scene = o.scene.resolve();
    const std::string method = default_method(o.method, scene);

    ThreadControl threads(o.threads);
    PipelineSettings config;
    config.method = parse_surface_method(method);
    config.scan = o.scan.resolve();
    o.slices.apply(config.slices);
    config.screen = o.screen.settings;
    config.volume = o.volume.resolve(o.slices.voxel);
    config.render = !o.no_render;
    config.pipelined = !o.no_pipeline;
    config.out_dir = o.no_render ? "" : o.out;
    parse_size(o.size, config.size.width, config.size.height);
    config.video_path = o.video;
    if (!o.video.empty()) {
        // yuv420p halves both sides; an odd size would have to be cropped or padded behind the user's back.
        if (config.size.width % 2 != 0 || config.size.height % 2 != 0)
            throw std::invalid_argument(fmt::format(
                "--video needs an even --size (yuv420p video halves both sides), got '{}'", o.size));
        silence_video_library_log();  // its notes would break the one-line error contract
    }

    // Each simulated frame's outside inputs: the scene's script or an input track. A recording logs
    // them, warm-up included, as they are handed out.
    InputTrack track;
    if (!o.inputs.empty()) track = read_input_track(o.inputs);
    std::vector<FrameInputs> inputs_log;
    if (!o.record.empty()) {
        config.hash_frames = true;
        inputs_log.resize(static_cast<std::size_t>(scene.warmup_frames) +
                          static_cast<std::size_t>(o.scene.frames));
    }
    if (!o.inputs.empty() || !o.record.empty()) {
        config.inputs = [&inputs_log, &scene, &track](std::uint64_t f) {
            const FrameInputs in = track.keys.empty() ? scripted_inputs(scene, f) : track.at(f);
            if (f < inputs_log.size()) inputs_log[f] = in;
            return in;
        };
    }

    std::unique_ptr<TraceRecorder> trace;
    if (!o.trace.empty()) {
        trace = std::make_unique<TraceRecorder>(static_cast<std::size_t>(threads.threads()));
        config.trace = trace.get();
    }
    FramePipeline pipeline(scene, config);
    if (!o.graph.empty()) io::write_text_file(o.graph, pipeline.graph().dot());
    if (Renderer* r = pipeline.renderer())
        fmt::print(stderr, "rivulet: scene '{}', {} threads, {} ({})\n", scene.name, threads.threads(),
                   r->gl_version(), r->gl_renderer());
    pipeline.warmup();
    pipeline.reserve_records(static_cast<std::size_t>(o.scene.frames));
    ProgressBar bar("frames", o.scene.frames);
    pipeline.run(o.scene.frames, [&bar](int i) { bar.update(i + 1); });
    pipeline.finish_video();

    const StageSummary summary = summarize(pipeline, o.timing_warmup);
    const auto& recs = pipeline.records();
    const FrameRecord& last = recs.back();
    fmt::print(
        "scene {} | method {} | {} frames | {} threads | {} particles, {} {}, {} isolated, {} "
        "triangles (last frame)\n",
        scene.name, method, recs.size(), threads.threads(), last.particles, last.groups,
        config.method == SurfaceMethod::kSlices   ? "blocks"
        : config.method == SurfaceMethod::kVolume ? "bricks"
                                                  : "groups",
        last.isolated, last.triangles);
    fmt::print("{}", format_stage_table(summary, config.render));
    // SPH: the solver's work and the density error it left, over the run (DFSPH: the error is bounded by
    // the scene's max_density_error unless a solve ran out of iterations, which is then said).
    nlohmann::json sph_json;
    if (scene.simulation == SimulationKind::kSph) {
        std::vector<double> substeps, iterations;
        double worst_error = 0;
        for (const FrameRecord& r : recs) {
            substeps.push_back(r.sph_substeps), iterations.push_back(r.sph_iterations);
            worst_error = std::max(worst_error, r.sph_density_error);
        }
        const auto most = [](const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); };
        const bool dfsph = scene.sph.solver == SphSolver::kDfsph;
        fmt::print("sph {}: substeps per frame median {} (max {})", dfsph ? "dfsph" : "wcsph",
                   median(substeps), most(substeps));
        if (dfsph)
            fmt::print(
                ", solver iterations per frame median {} (max {}), density error at most {:.3f} % (bound "
                "{} %)",
                median(iterations), most(iterations), 100.0 * worst_error, scene.sph.max_density_error);
        fmt::print("\n");
        if (dfsph && worst_error > 0.01 * double(scene.sph.max_density_error) + 1e-9)
            fmt::print(stderr,
                       "rivulet: warning: a substep's pressure solve stopped at sph.max_iterations ({}) with "
                       "{:.3f} % density error left (bound {} %)\n",
                       scene.sph.max_iterations, 100.0 * worst_error, scene.sph.max_density_error);
        sph_json = {
            {"solver", dfsph ? "dfsph" : "wcsph"}, {"substeps_median", median(substeps)},
            {"substeps_max", most(substeps)},      {"iterations_median", median(iterations)},
            {"iterations_max", most(iterations)},  {"density_error_max_percent", 100.0 * worst_error}};
    }
    // A limit that was hit is reported (DESIGN §3.6): the picture is right but drawn with fewer cylinders.
    std::size_t short_frames = 0, worst = 0;
    for (const FrameRecord& r : recs)
        if (r.pool_exhausted > 0) ++short_frames, worst = std::max<std::size_t>(worst, r.pool_exhausted);
    if (short_frames > 0)
        fmt::print(
            stderr,
            "rivulet: warning: the cylinder pool (--max-groups {}) ran out in {} of {} frames; up to {} "
            "particle entries were drawn as spheres instead\n",
            config.scan.max_groups, short_frames, recs.size(), worst);
    if (!config.out_dir.empty()) fmt::print("pictures: {}/frame_*.png\n", config.out_dir);
    if (const VideoWriter* v = pipeline.video()) {
        const VideoFrameRate rate = v->frame_rate();
        fmt::print("video: {} ({}, {}x{}, {} fps, {} frames)\n", v->path(), v->codec_description(),
                   v->width(), v->height(),
                   rate.den == 1 ? fmt::format("{}", rate.num) : fmt::format("{}/{}", rate.num, rate.den),
                   v->frames());
    }
    if (trace) {
        const nlohmann::json capture = chrome_trace(*trace, pipeline.graph());
        write_chrome_trace(o.trace, capture);
        fmt::print("{}", format_trace_summary(summarize_trace(capture)));
        fmt::print("trace: {} (open in Perfetto UI or chrome://tracing){}\n", o.trace,
                   trace->dropped()
                       ? fmt::format(", {} zones dropped: a trace keeps at most {} (docs/tracing.md)",
                                     trace->dropped(), trace->max_zones())
                       : "");
    }
    if (!o.record.empty()) {
        write_recording(o.record, make_recording(pipeline, inputs_log));
        fmt::print("recording: {} ({} frames; replay with: rivulet replay {})\n", o.record, recs.size(),
                   o.record);
    }
    if (!o.json.empty()) {
        nlohmann::json j = stage_json(summary);
        j["scene"] = scene.name;
        j["method"] = surface_method_name(pipeline.config().method);
        j["threads"] = threads.threads();
        j["pipelined"] = config.pipelined;
        j["particles"] = last.particles;
        j["groups"] = last.groups;
        j["triangles"] = last.triangles;
        j["pool_exhausted_frames"] = short_frames;
        if (!sph_json.is_null()) j["sph"] = sph_json;
        write_json_file(o.json, j);
    }
    return 0;
}

}  // namespace

void add_run_command(CLI::App& app, int& status) {
    auto opts = std::make_shared<RunOptions>();
    CLI::App* cmd =
        app.add_subcommand("run", "Simulate a scene, extract its surface and render it, frame after frame");
    add_method_option(*cmd, opts->method, true);
    opts->scene.add_to(*cmd, "Frames to render");
    add_threads_option(*cmd, opts->threads, "Threads for TBB and llvmpipe together (0 = all)");
    cmd->add_option("--out", opts->out, "Directory for PNG frames (empty: no pictures)")
        ->capture_default_str();
    CLI::Option* video = cmd->add_option(
        "--video", opts->video,
        "Also encode the frames into this video at the scene's frame rate (H.264, else MPEG-4; "
        "container by extension: .mp4, .mkv, .mov, .avi); needs an even --size");
    cmd->add_option("--size", opts->size, "Picture size WxH")->capture_default_str();
    cmd->add_option("--json", opts->json, "Write the timing summary as JSON");
    cmd->add_option("--trace", opts->trace,
                    "Write every job's zones as Chrome Trace Event JSON (Perfetto, chrome://tracing)");
    cmd->add_option("--graph", opts->graph,
                    "Write the frame graph (every job, its dependencies, the nested jobs) as Graphviz DOT, "
                    "e.g. for `dot -Tsvg`");
    cmd->add_option("--record", opts->record,
                    "Write a recording (scene, settings, per-frame inputs and hashes) for rivulet replay");
    cmd->add_option("--inputs", opts->inputs,
                    "Take each frame's outside inputs (the tank's offset, the emitters' scale) from this "
                    "track, lines 'frame dx dy dz [emitter_scale]' interpolated linearly, instead of the "
                    "scene's script (docs/recording.md)");
    cmd->add_option("--timing-warmup", opts->timing_warmup,
                    "Frames rendered first and left out of the medians (benchmarks)")
        ->check(CLI::Range(0, kMaxRunFrames - 1));  // fewer than --frames, checked in run()
    cmd->add_flag("--no-pipeline", opts->no_pipeline, "Extract frame N+1 only after frame N is rendered");
    cmd->add_flag("--no-render", opts->no_render, "Simulate and extract only (no GL, no pictures)")
        ->excludes(video);
    opts->scan.add_to(*cmd);
    opts->slices.add_to(*cmd);
    opts->screen.add_to(*cmd);
    opts->volume.add_to(*cmd, false);
    cmd->callback([opts, &status] { status = run(*opts); });
}

}  // namespace rivulet::cli
