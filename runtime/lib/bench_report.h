#pragma once
// `rivulet bench` results: one case per scene x method x thread count, with speedup and parallel
// efficiency against the same scene and method at its smallest thread count; written as bench.json, a
// Markdown table and gnuplot input (frames/s against threads with the ideal-scaling line; stacked
// per-stage bars).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace rivulet {

struct BenchCase {
    std::string scene, method;
    int threads = 1;
    nlohmann::json run;  // what `rivulet run --json` wrote for this case
    // Filled by derive_scaling():
    double frames_per_second = 0;
    double speedup = 1;     // fps / fps at the base thread count
    double efficiency = 1;  // speedup / (threads / base threads)
};

// Reads frame_ms from each case's run JSON and fills fps, speedup and efficiency. Throws
// std::invalid_argument when a run lacks frame_ms or it is not positive.
void derive_scaling(std::vector<BenchCase>& cases);

nlohmann::json bench_json(const std::vector<BenchCase>& cases, const nlohmann::json& meta);
std::string bench_markdown(const std::vector<BenchCase>& cases, const nlohmann::json& meta);

// Files for gnuplot in `dir`: scaling.dat, stages.dat and plots.gp (which writes scaling.png and
// stages.png when run from `dir`). Returns the script's path.
std::string write_gnuplot_inputs(const std::vector<BenchCase>& cases, const std::string& dir);

}  // namespace rivulet
