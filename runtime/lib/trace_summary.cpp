#include "runtime/lib/trace_summary.h"

#include <fmt/format.h>
#include <algorithm>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "runtime/lib/stage_summary.h"

namespace rivulet {
namespace {

struct Zone {
    std::string name;
    int frame = 0, tid = 0;
    double begin = 0, end = 0;  // µs
};

struct Span {
    double begin = 1e300, end = -1e300;
    void add(double b, double e) { begin = std::min(begin, b), end = std::max(end, e); }
    double length() const { return end > begin ? end - begin : 0.0; }
};

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
    return v[std::min(i, v.size() - 1)];
}

// Longest chain of job spans through the dependency graph (jobs listed in topological order).
std::pair<double, std::vector<std::string>> critical_path(
    const std::vector<std::pair<std::string, std::vector<std::string>>>& jobs,
    const std::map<std::string, Span>& spans) {
    std::map<std::string, double> longest;
    std::map<std::string, std::string> via;
    for (const auto& [name, after] : jobs) {
        const auto it = spans.find(name);
        const double own = it == spans.end() ? 0.0 : it->second.length();
        double before = 0;
        for (const std::string& d : after) {
            if (longest[d] > before || !via.count(name)) {
                before = std::max(before, longest[d]);
                via[name] = d;
            }
        }
        longest[name] = before + own;
    }
    std::string end;
    double length = -1;
    for (const auto& [name, after] : jobs)
        if (longest[name] > length) length = longest[name], end = name;
    std::vector<std::string> path;
    for (std::string at = end; !at.empty();) {
        path.push_back(at);
        const auto it = via.find(at);
        at = it == via.end() ? std::string() : it->second;
    }
    std::reverse(path.begin(), path.end());
    return {std::max(length, 0.0), path};
}

}  // namespace

TraceSummary summarize_trace(const nlohmann::json& trace) {
    if (!trace.contains("traceEvents") || !trace["traceEvents"].is_array())
        throw std::runtime_error("not a Chrome trace: no traceEvents array");
    const auto other = trace.value("otherData", nlohmann::json::object());
    if (!other.contains("jobs"))
        throw std::runtime_error("not a Rivulet capture: otherData.jobs (the frame graph) is missing");
    // Nested jobs run inside their parent's zone: the parent's span covers them on the critical path,
    // and their zones (not the parent's) count as busy time, so no work is counted twice.
    std::vector<std::pair<std::string, std::vector<std::string>>> jobs;
    std::vector<std::string> nested, parents;
    for (const auto& j : other["jobs"]) {
        if (j.contains("nested_in")) {
            nested.push_back(j.at("name"));
            parents.push_back(j.at("nested_in"));
            continue;
        }
        jobs.emplace_back(j.at("name"), j.at("after").get<std::vector<std::string>>());
    }
    const auto is_parent = [&parents](const std::string& name) {
        return std::find(parents.begin(), parents.end(), name) != parents.end();
    };

    std::vector<Zone> zones;
    std::map<int, std::string> thread_names;
    for (const auto& e : trace["traceEvents"]) {
        const std::string ph = e.value("ph", "");
        if (ph == "M" && e.value("name", "") == "thread_name")
            thread_names[e.at("tid")] = e.at("args").at("name");
        if (ph != "X") continue;
        Zone z{e.at("name"), e.at("args").value("frame", 0), e.value("tid", 0), e.at("ts"), 0};
        z.end = z.begin + e.at("dur").get<double>();
        zones.push_back(std::move(z));
    }
    if (zones.empty()) throw std::runtime_error("the trace holds no zones");

    TraceSummary s;
    // Per job, in graph order, then the render-side zones.
    std::vector<std::string> order;
    for (const auto& [name, after] : jobs) order.push_back(name);
    order.insert(order.end(), nested.begin(), nested.end());
    for (const Zone& z : zones)
        if (std::find(order.begin(), order.end(), z.name) == order.end()) order.push_back(z.name);
    for (const std::string& name : order) {
        std::vector<double> d;
        for (const Zone& z : zones)
            if (z.name == name) d.push_back((z.end - z.begin) * 1e-3);
        if (d.empty()) continue;
        JobStats js{
            name, d.size(), percentile(d, 0.5), percentile(d, 0.95), *std::max_element(d.begin(), d.end()),
            0};
        for (double v : d) js.total_ms += v;
        s.jobs.push_back(js);
    }

    // Wall, busy, idle per thread.
    double first = 1e300, last = -1e300;
    std::map<int, double> busy;
    for (const Zone& z : zones) {
        first = std::min(first, z.begin), last = std::max(last, z.end);
        if (!is_parent(z.name)) busy[z.tid] += z.end - z.begin;
    }
    s.wall_ms = (last - first) * 1e-3;
    for (const auto& [tid, name] : thread_names) busy.emplace(tid, 0.0);
    for (const auto& [tid, us] : busy) {
        s.busy_ms += us * 1e-3;
        const auto n = thread_names.find(tid);
        s.threads.push_back({n == thread_names.end() ? fmt::format("thread {}", tid) : n->second, us * 1e-3,
                             s.wall_ms > 0 ? 1.0 - us * 1e-3 / s.wall_ms : 0.0});
    }
    s.parallelism = s.wall_ms > 0 ? s.busy_ms / s.wall_ms : 0;

    // Per frame: job spans (critical path) and the extraction span (overlap with the previous render).
    std::map<int, std::map<std::string, Span>> spans;
    std::map<int, Span> extraction, render;
    for (const Zone& z : zones) {
        if (z.name == "render") {
            render[z.frame].add(z.begin, z.end);
        } else if (z.name != "png_encode") {
            spans[z.frame][z.name].add(z.begin, z.end);
            extraction[z.frame].add(z.begin, z.end);
        }
    }
    std::vector<std::pair<double, int>> lengths;
    for (const auto& [frame, job_spans] : spans)
        lengths.emplace_back(critical_path(jobs, job_spans).first, frame);
    std::sort(lengths.begin(), lengths.end());
    if (!lengths.empty()) {
        const int median_frame = lengths[lengths.size() / 2].second;
        const auto [length, path] = critical_path(jobs, spans[median_frame]);
        s.critical_path_ms = length * 1e-3;
        s.critical_path = path;
    }
    std::vector<double> overlap, share;
    for (const auto& [frame, r] : render) {
        const auto next = extraction.find(frame + 1);
        if (next == extraction.end()) continue;
        const double o =
            std::max(0.0, std::min(r.end, next->second.end) - std::max(r.begin, next->second.begin));
        overlap.push_back(o * 1e-3);
        share.push_back(r.length() > 0 ? o / r.length() : 0.0);
    }
    s.overlap_ms = median(overlap);
    s.overlap_share = median(share);
    s.frames = static_cast<int>(std::max(spans.size(), render.size()));
    return s;
}

TraceSummary summarize_trace_file(const std::string& path) {
    std::ifstream f(path);
    if (!f) throw std::runtime_error("cannot open " + path);
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(f);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(path + ": not JSON: " + e.what());
    }
    try {
        return summarize_trace(doc);
    } catch (const nlohmann::json::exception& e) {
        throw std::runtime_error(path + ": malformed trace: " + e.what());
    } catch (const std::runtime_error& e) {
        throw std::runtime_error(path + ": " + e.what());
    }
}

std::string format_trace_summary(const TraceSummary& s) {
    std::string t = fmt::format("{:<22} {:>7} {:>10} {:>10} {:>10} {:>11}\n", "job", "zones", "median ms",
                                "p95 ms", "max ms", "total ms");
    for (const JobStats& j : s.jobs)
        t += fmt::format("{:<22} {:>7} {:>10.3f} {:>10.3f} {:>10.3f} {:>11.3f}\n", j.name, j.count,
                         j.median_ms, j.p95_ms, j.max_ms, j.total_ms);
    std::string path;
    for (const std::string& p : s.critical_path) path += (path.empty() ? "" : " -> ") + p;
    t += fmt::format("critical path ({} frames, median frame): {:.3f} ms: {}\n", s.frames, s.critical_path_ms,
                     path);
    t += fmt::format("parallelism: {:.2f} (busy {:.1f} ms over {:.1f} ms wall)\n", s.parallelism, s.busy_ms,
                     s.wall_ms);
    for (const ThreadIdle& th : s.threads)
        t += fmt::format("  {:<16} busy {:>9.1f} ms, idle {:>5.1f} %\n", th.name, th.busy_ms,
                         100.0 * th.idle_share);
    t += fmt::format("render N overlapping extraction N+1: {:.3f} ms median ({:.1f} % of the render)\n",
                     s.overlap_ms, 100.0 * s.overlap_share);
    return t;
}

}  // namespace rivulet
