#include "runtime/lib/stage_summary.h"

#include <fmt/format.h>
#include <algorithm>
#include <nlohmann/json.hpp>

namespace rivulet {

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    if (v.size() % 2) return *mid;
    return 0.5 * (*mid + *std::max_element(v.begin(), mid));
}

std::string format_stage_table(const StageSummary& s, bool with_render) {
    std::string t = fmt::format("{:<22} {:>10}\n", "stage", "median ms");
    t += fmt::format("{:-<22} {:->10}\n", "", "");
    for (const auto& [name, ms] : s.stage_ms) t += fmt::format("{:<22} {:>10.3f}\n", name, ms);
    t += fmt::format("{:-<22} {:->10}\n", "", "");
    t += fmt::format("{:<22} {:>10.3f}\n", "extract (graph)", s.extract_ms);
    if (with_render) t += fmt::format("{:<22} {:>10.3f}\n", "render (main thread)", s.render_ms);
    t += fmt::format("{:<22} {:>10.3f}\n", "frame", s.frame_ms);
    t += fmt::format("{:<22} {:>10.1f}\n", "frames/s", s.frames_per_second);
    return t;
}

nlohmann::json stage_json(const StageSummary& s) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& [name, ms] : s.stage_ms) stages[name] = ms;
    return {{"frames", s.frames},         {"stages", stages},
            {"frame_ms", s.frame_ms},     {"render_ms", s.render_ms},
            {"extract_ms", s.extract_ms}, {"frames_per_second", s.frames_per_second}};
}

}  // namespace rivulet
