// Nested jobs of the frame graph: a serial job that loops (SPH substeps) runs its nested jobs' items on
// the workers; they are timed, counted and traced as jobs of their own, and the trace summary does not
// count the parent's zone as busy time on top of them.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <vector>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/thread_control.h"
#include "runtime/lib/trace_recorder.h"
#include "runtime/lib/trace_summary.h"

using namespace rivulet;

TEST(FrameGraph, NestedJobsRunEveryItemOfEveryCallAndAreTracedAsJobs) {
    ThreadControl control(2);
    TraceRecorder recorder(2);
    FrameGraph graph;
    std::vector<int> out(64, 0);
    FrameGraph::JobId nested = 0;
    const auto parent = graph.serial("loop", [&] {
        for (int s = 0; s < 3; ++s)
            graph.run_nested(nested, out.size(), [&](std::size_t i) { out[i] += int(i); });
    });
    nested = graph.nested("loop.phase", parent);
    graph.serial("after", [] {}, {parent});
    graph.attach_trace(&recorder);
    graph.set_frame(7);
    graph.run();
    for (std::size_t i = 0; i < out.size(); ++i) ASSERT_EQ(out[i], 3 * int(i));
    EXPECT_EQ(graph.job_items(nested), 3 * out.size());
    EXPECT_GT(graph.job_ms(nested), 0.0);
    EXPECT_LE(graph.job_ms(nested), graph.job_ms(parent));
    EXPECT_EQ(graph.job_parent(nested), std::int64_t(parent));
    EXPECT_EQ(graph.job_parent(parent), -1);
    graph.run();  // the sum restarts every frame
    EXPECT_EQ(graph.job_items(nested), 3 * out.size());

    const nlohmann::json trace = chrome_trace(recorder, graph);
    std::size_t nested_zones = 0;
    for (const auto& e : trace["traceEvents"])
        if (e.value("name", "") == "loop.phase" && e["ph"] == "X") {
            ++nested_zones;
            EXPECT_EQ(e["args"]["frame"], 7);
        }
    EXPECT_EQ(nested_zones, 2 * 3 * out.size());
    bool listed = false;
    for (const auto& j : trace["otherData"]["jobs"])
        if (j["name"] == "loop.phase") listed = j.value("nested_in", "") == "loop";
    EXPECT_TRUE(listed);
    const TraceSummary s = summarize_trace(trace);
    // Busy time counts the nested items, not the parent zone wrapped around them as well.
    EXPECT_LE(s.busy_ms, s.wall_ms * 2.0 + 1e-9);
}

TEST(FrameGraph, NestedJobsNeedASerialParentAndNoJobFollowsThem) {
    FrameGraph g;
    const auto par = g.parallel(
        "items", [] { return std::size_t(1); }, [](std::size_t) {});
    EXPECT_THROW(g.nested("n", par), std::logic_error);
    const auto ser = g.serial("s", [] {});
    const auto n = g.nested("n", ser);
    g.serial("after_nested", [] {}, {n});
    EXPECT_THROW(g.run(), std::logic_error);
}
