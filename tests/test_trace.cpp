// Trace capture: zones of every job and item land in per-thread buffers and come out as Chrome Trace
// Event JSON with thread names, frame markers and a flow from each frame's extraction to its render.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "runtime/lib/trace_recorder.h"
#include "support/test_support.h"

using namespace rivulet;

TEST(Trace, RunWritesZonesThreadsFramesAndHandOverFlows) {
    constexpr int kFrames = 4;
    ThreadControl control(2);
    TraceRecorder recorder(2, 4096);
    PipelineConfig config;
    config.size = {160, 90};
    config.trace = &recorder;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 30;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.run(kFrames);
    const std::string path = rivulet::test::temp_path("trace.json");
    write_chrome_trace(path, recorder);
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
        if (name == "grouping" || name == "upload_staging") {
            EXPECT_EQ(zones[name], kFrames) << name;
        }
    }
    EXPECT_EQ(zones["render"], kFrames);
    // Parallel jobs carry their item ids: deform has one zone per group, numbered 0..groups-1.
    ASSERT_FALSE(items_of_frame0["deform"].empty());
    EXPECT_EQ(*items_of_frame0["deform"].begin(), 0);
    EXPECT_EQ(static_cast<int>(items_of_frame0["deform"].size()), *items_of_frame0["deform"].rbegin() + 1);
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

TEST(Trace, FullBuffersDropZonesInsteadOfGrowing) {
    TraceRecorder recorder(1, 3);
    const std::uint16_t name = recorder.intern("job");
    EXPECT_EQ(recorder.intern("job"), name);
    for (int i = 0; i < 5; ++i) recorder.record(name, 0, i, i, i + 1);
    EXPECT_EQ(recorder.zones().size(), 3u);
    EXPECT_EQ(recorder.dropped(), 2u);
}
