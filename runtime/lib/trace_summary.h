#pragma once
// What a capture says (issue 5's `rivulet trace-summary`): per-job statistics, the critical path of a
// frame, parallelism, idle share per thread, and how much of render N overlaps extraction N+1. Works on
// the Chrome Trace JSON that write_chrome_trace() produces (the job graph travels in its otherData).
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace rivulet {

struct JobStats {
    std::string name;
    std::size_t count = 0;  // zones (a parallel job has one per item)
    double median_ms = 0, p95_ms = 0, max_ms = 0, total_ms = 0;
};

struct ThreadIdle {
    std::string name;
    double busy_ms = 0, idle_share = 0;
};

struct TraceSummary {
    std::vector<JobStats> jobs;              // graph order, then render / png_encode
    std::vector<std::string> critical_path;  // jobs of the median frame's longest dependency chain
    double critical_path_ms = 0;             // its length (sum of job spans), median over frames
    double wall_ms = 0, busy_ms = 0, parallelism = 0;
    std::vector<ThreadIdle> threads;
    double overlap_ms = 0;     // median over frames: render N ∩ extraction N+1
    double overlap_share = 0;  // of render N's duration
    int frames = 0;
};

// Throws std::runtime_error naming what is missing when `trace` is not a Rivulet capture.
TraceSummary summarize_trace(const nlohmann::json& trace);
TraceSummary summarize_trace_file(const std::string& path);
std::string format_trace_summary(const TraceSummary& s);

}  // namespace rivulet
