// Trace capture: zones of every job and item land in per-thread buffers and come out as Chrome Trace
// Event JSON with thread names, frame markers and a flow from each frame's extraction to its render.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "runtime/lib/trace_recorder.h"
#include "runtime/lib/trace_summary.h"
#include "support/test_support.h"

using namespace rivulet;

TEST(Trace, RunWritesZonesThreadsFramesAndHandOverFlows) {
    constexpr int kFrames = 4;
    ThreadControl control(2);
    TraceRecorder recorder(2);
    PipelineSettings config;
    config.size = {160, 90};
    config.trace = &recorder;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 30;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.run(kFrames);
    const std::string path = rivulet::test::temp_path("trace.json");
    write_chrome_trace(path, chrome_trace(recorder, pipeline.graph()));
    EXPECT_EQ(recorder.dropped(), 0u);

    std::ifstream f(path);
    const auto doc = nlohmann::json::parse(f);
    std::map<std::string, int> zones;
    std::map<std::string, std::set<int>> items_of_frame0;
    std::map<int, double> flow_start, flow_end;
    std::set<std::string> thread_names;
    int frame_markers = 0;
    for (const auto& e : doc["traceEvents"]) {
        const std::string ph = e["ph"];
        if (ph == "X") {
            const std::string name = e["name"];
            ++zones[name];
            EXPECT_GE(e["dur"].get<double>(), 0.0);
            const int frame = e["args"]["frame"];
            EXPECT_GE(frame, 0);
            EXPECT_LT(frame, kFrames);
            if (e["args"].contains("item") && frame == 0)
                items_of_frame0[name].insert(e["args"]["item"].get<int>());
            if (name == "render") {
                EXPECT_EQ(e["tid"], 0) << "render runs on the main thread";
            }
        } else if (ph == "M" && e["name"] == "thread_name") {
            thread_names.insert(e["args"]["name"].get<std::string>());
        } else if (ph == "s") {
            flow_start[e["id"].get<int>()] = e["ts"].get<double>();
        } else if (ph == "f") {
            flow_end[e["id"].get<int>()] = e["ts"].get<double>();
        } else if (ph == "i") {
            ++frame_markers;
        }
    }
    // Every job of the graph, once per frame (serial) or once per item (parallel).
    for (FrameGraph::JobId j = 0; j < pipeline.graph().job_count(); ++j) {
        const std::string& name = pipeline.graph().job_name(j);
        ASSERT_TRUE(zones.count(name)) << name;
        if (name == "oriented.cylinders" || name == "upload_staging") {
            EXPECT_EQ(zones[name], kFrames) << name;
        }
    }
    EXPECT_EQ(zones["render"], kFrames);
    // Parallel jobs carry their item ids: oriented.rings has one zone per branch, numbered 0..branches-1.
    ASSERT_FALSE(items_of_frame0["oriented.rings"].empty());
    EXPECT_EQ(*items_of_frame0["oriented.rings"].begin(), 0);
    EXPECT_EQ(static_cast<int>(items_of_frame0["oriented.rings"].size()),
              *items_of_frame0["oriented.rings"].rbegin() + 1);
    EXPECT_TRUE(thread_names.count("main (render)"));
    EXPECT_TRUE(thread_names.count("worker 1"));
    EXPECT_EQ(frame_markers, kFrames);
    // Each frame's extraction hands over before its render starts.
    ASSERT_EQ(flow_start.size(), static_cast<std::size_t>(kFrames));
    for (const auto& [id, ts] : flow_start) {
        ASSERT_TRUE(flow_end.count(id)) << "frame " << id;
        EXPECT_LE(ts, flow_end[id]) << "frame " << id;
    }
}

TEST(Trace, RenderPassesAreZonesInsideTheirRender) {
    for (SurfaceMethod method : {SurfaceMethod::kSlices, SurfaceMethod::kScreen}) {
        ThreadControl control(2);
        TraceRecorder recorder(2);
        PipelineSettings config;
        config.size = {160, 90};
        config.method = method;
        config.trace = &recorder;
        SceneDesc scene = make_builtin_scene("fountain");
        scene.warmup_frames = 30;
        FramePipeline pipeline(scene, config);
        pipeline.warmup();
        pipeline.run(2);
        std::map<std::uint32_t, TraceZone> render_of_frame;
        std::map<std::string, std::vector<TraceZone>> parts;
        for (const TraceZone& z : recorder.zones()) {
            const std::string& name = recorder.names()[z.name];
            if (name == "render") render_of_frame[z.frame] = z;
            if (name.rfind("render.", 0) == 0 || name.rfind("screen.", 0) == 0) parts[name].push_back(z);
        }
        ASSERT_EQ(render_of_frame.size(), 2u);
        const std::vector<std::string> expected =
            method == SurfaceMethod::kSlices
                ? std::vector<std::string>{"render.shadow", "render.scene", "render.water_thickness",
                                           "render.water"}
                : std::vector<std::string>{"render.shadow",   "render.scene",     "render.screen",
                                           "screen.depth",    "screen.smoothing", "screen.thickness",
                                           "screen.composite"};
        for (const std::string& name : expected) {
            ASSERT_EQ(parts[name].size(), 2u) << name << " in " << surface_method_name(method);
            for (const TraceZone& z : parts[name]) {
                const TraceZone& r = render_of_frame[z.frame];
                EXPECT_GE(z.begin_ns, r.begin_ns) << name;
                EXPECT_LE(z.end_ns, r.end_ns) << name;
                EXPECT_EQ(z.thread, r.thread) << name;
            }
        }
        // The mesh methods have no screen pass.
        if (method == SurfaceMethod::kSlices) {
            EXPECT_TRUE(parts["render.screen"].empty());
        }
    }
}

TEST(Trace, FullBuffersDropZonesInsteadOfGrowing) {
    TraceRecorder recorder(1, 3);
    const std::uint16_t name = recorder.intern("job");
    EXPECT_EQ(recorder.intern("job"), name);
    for (int i = 0; i < 5; ++i) recorder.record(name, 0, i, i, i + 1);
    EXPECT_EQ(recorder.zones().size(), 3u);
    EXPECT_EQ(recorder.dropped(), 2u);
}

namespace {

nlohmann::json zone(const std::string& name, int frame, int tid, double ts, double dur) {
    return {{"name", name},
            {"ph", "X"},
            {"pid", 1},
            {"tid", tid},
            {"ts", ts},
            {"dur", dur},
            {"args", {{"frame", frame}}}};
}

}  // namespace

// A hand-made capture: A -> {B, C} -> D, two frames, a render of frame 0 overlapping frame 1's extraction.
TEST(TraceSummary, CriticalPathParallelismAndOverlapOfAHandMadeTrace) {
    nlohmann::json events = nlohmann::json::array();
    events.push_back({{"name", "thread_name"},
                      {"ph", "M"},
                      {"pid", 1},
                      {"tid", 0},
                      {"args", {{"name", "main (render)"}}}});
    events.push_back(
        {{"name", "thread_name"}, {"ph", "M"}, {"pid", 1}, {"tid", 1}, {"args", {{"name", "worker 1"}}}});
    // Frame 0: the chain through C (10 + 20 + 5 = 35 µs).
    for (const auto& z : {zone("A", 0, 0, 0, 10), zone("B", 0, 0, 10, 5), zone("C", 0, 1, 10, 10),
                          zone("C", 0, 0, 12, 18), zone("D", 0, 0, 30, 5)})
        events.push_back(z);
    events.push_back(zone("render", 0, 0, 40, 100));
    // Frame 1, extracted on the worker during render 0: the chain through B (10 + 25 + 5 = 40 µs).
    for (const auto& z : {zone("A", 1, 1, 100, 10), zone("B", 1, 1, 110, 25), zone("C", 1, 1, 110, 5),
                          zone("D", 1, 1, 135, 5)})
        events.push_back(z);
    const nlohmann::json jobs = {{{"name", "A"}, {"after", nlohmann::json::array()}},
                                 {{"name", "B"}, {"after", {"A"}}},
                                 {{"name", "C"}, {"after", {"A"}}},
                                 {{"name", "D"}, {"after", {"B", "C"}}}};
    const TraceSummary s = summarize_trace({{"traceEvents", events}, {"otherData", {{"jobs", jobs}}}});

    EXPECT_EQ(s.frames, 2);
    // Median of the two frames' paths (35 and 40 µs) is the upper one: A -> B -> D.
    EXPECT_EQ(s.critical_path, (std::vector<std::string>{"A", "B", "D"}));
    EXPECT_NEAR(s.critical_path_ms, 0.040, 1e-9);
    // Busy 48 + 45 + 100 µs over a wall of 140 µs.
    EXPECT_NEAR(s.busy_ms, 0.193, 1e-9);
    EXPECT_NEAR(s.wall_ms, 0.140, 1e-9);
    EXPECT_NEAR(s.parallelism, 193.0 / 140.0, 1e-9);
    // Render 0 spans [40, 140]; extraction 1 spans [100, 140]: 40 µs, 40 % of the render.
    EXPECT_NEAR(s.overlap_ms, 0.040, 1e-9);
    EXPECT_NEAR(s.overlap_share, 0.4, 1e-9);
    // C has three zones: 10, 18 and 5 µs.
    const auto c =
        std::find_if(s.jobs.begin(), s.jobs.end(), [](const JobStats& j) { return j.name == "C"; });
    ASSERT_NE(c, s.jobs.end());
    EXPECT_EQ(c->count, 3u);
    EXPECT_NEAR(c->median_ms, 0.010, 1e-9);
    EXPECT_NEAR(c->max_ms, 0.018, 1e-9);
    EXPECT_NEAR(c->total_ms, 0.033, 1e-9);
    ASSERT_EQ(s.threads.size(), 2u);
    EXPECT_EQ(s.threads[1].name, "worker 1");
    EXPECT_NEAR(s.threads[1].busy_ms, (10 + 10 + 25 + 5 + 5) * 1e-3, 1e-9);
}

TEST(TraceSummary, RejectsFilesThatAreNotCaptures) {
    EXPECT_THROW(summarize_trace(nlohmann::json{{"foo", 1}}), std::runtime_error);
    EXPECT_THROW(summarize_trace(nlohmann::json{{"traceEvents", nlohmann::json::array()}}),
                 std::runtime_error);
    const std::string path = rivulet::test::temp_path("not-json.json");
    std::ofstream(path) << "{ not json";
    EXPECT_THROW(summarize_trace_file(path), std::runtime_error);
}
