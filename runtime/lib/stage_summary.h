#pragma once
// Per-stage medians of a run or of repeated extractions, printed as a table and written as JSON.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace rivulet {

double median(std::vector<double> values);

struct StageSummary {
    std::vector<std::pair<std::string, double>> stage_ms;  // per job, median ms, graph order
    double frame_ms = 0, render_ms = 0, extract_ms = 0;    // medians
    double frames_per_second = 0;
    int frames = 0;
};

// Fixed-width table for a terminal.
std::string format_stage_table(const StageSummary& s, bool with_render);
nlohmann::json stage_json(const StageSummary& s);

}  // namespace rivulet
