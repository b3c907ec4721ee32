#include "runtime/lib/trace_summary.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <numeric>
#include <stdexcept>
#include <unordered_map>

#include "runtime/lib/stage_summary.h"
#include "systems/io/io_limits.h"
#include "systems/io/json_file.h"

namespace rivulet {
namespace {

using nlohmann::json;

// A capture comes from `rivulet run --trace` or from another tool: every number is checked before it is
// used as an index, a frame or a time, and the job graph before it is walked.
constexpr std::size_t kMaxJobs = 1024;
constexpr std::size_t kMaxDependencies = 65536;
constexpr std::int64_t kMaxFrame = 1'000'000'000;
constexpr std::int64_t kMaxTid = 65535;
constexpr double kMaxMicroseconds = 1e15;  // 31 years
// Frames x jobs bounds the critical-path work (one longest-path pass over the graph per frame).
constexpr double kMaxPathWork = 2.5e8;

[[noreturn]] void fail(const std::string& what) {
    throw std::runtime_error(what);
}

std::int64_t integer_in(const json& j, std::int64_t lo, std::int64_t hi, const std::string& where) {
    if (j.is_number_integer()) {
        const bool fits = j.is_number_unsigned() ? j.get<std::uint64_t>() <= std::uint64_t(hi)
                                                 : j.get<std::int64_t>() >= lo && j.get<std::int64_t>() <= hi;
        if (fits) return j.get<std::int64_t>();
    }
    fail(fmt::format("{} must be an integer in [{}, {}], got {}", where, lo, hi, j.dump()));
}

double time_in(const json& j, double lo, const std::string& where) {
    if (j.is_number()) {
        const double v = j.get<double>();
        if (std::isfinite(v) && v >= lo && v <= kMaxMicroseconds) return v;
    }
    fail(fmt::format("{} must be a number of microseconds in [{}, {}], got {}", where, lo, kMaxMicroseconds,
                     j.dump()));
}

const std::string& string_at(const json& object, const char* key, const std::string& where) {
    const auto it = object.find(key);
    if (it == object.end() || !it->is_string()) fail(fmt::format("{}.{} must be a string", where, key));
    return it->get_ref<const std::string&>();
}

struct Zone {
    std::size_t name = 0;  // index into Graph::names
    std::int64_t frame = 0;
    int tid = 0;
    double begin = 0, end = 0;  // µs
};

struct Span {
    double begin = 1e300, end = -1e300;
    void add(double b, double e) { begin = std::min(begin, b), end = std::max(end, e); }
    double length() const { return end > begin ? end - begin : 0.0; }
};

// The frame graph of otherData.jobs, checked: unique names, dependencies on known jobs, no cycle.
// Names [0, jobs) are the graph's jobs in file order; zone names outside the graph follow.
struct Graph {
    std::vector<std::string> names;
    std::unordered_map<std::string, std::size_t> index;
    std::size_t jobs = 0;
    std::vector<bool> nested, parent;             // per job
    std::vector<std::vector<std::size_t>> after;  // per job (nested jobs: none that count)
    std::vector<std::size_t> topological;         // top-level jobs, dependencies first

    std::size_t intern(const std::string& name) {
        const auto [it, added] = index.emplace(name, names.size());
        if (added) names.push_back(name);
        return it->second;
    }
};

Graph read_graph(const json& list) {
    if (!list.is_array()) fail("otherData.jobs must be an array");
    if (list.size() > kMaxJobs)
        fail(fmt::format("otherData.jobs lists {} jobs (limit {})", list.size(), kMaxJobs));
    Graph g;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string where = fmt::format("otherData.jobs[{}]", i);
        if (!list[i].is_object()) fail(where + " must be an object");
        const std::string& name = string_at(list[i], "name", where);
        if (g.index.count(name)) fail(fmt::format("{}: job '{}' is listed twice", where, name));
        g.intern(name);
    }
    g.jobs = g.names.size();
    g.nested.assign(g.jobs, false), g.parent.assign(g.jobs, false), g.after.resize(g.jobs);
    const auto job_named = [&g](const std::string& name, const std::string& where) {
        const auto it = g.index.find(name);
        if (it == g.index.end())
            fail(fmt::format("{} names '{}', which is not a job of the graph", where, name));
        return it->second;
    };
    std::size_t dependencies = 0;
    for (std::size_t i = 0; i < g.jobs; ++i) {
        const json& j = list[i];
        const std::string where = fmt::format("otherData.jobs[{}] '{}'", i, g.names[i]);
        if (const auto it = j.find("nested_in"); it != j.end()) {
            if (!it->is_string()) fail(where + ": nested_in must be a string");
            const std::size_t p = job_named(it->get<std::string>(), where + ": nested_in");
            if (p == i) fail(where + " is nested in itself");
            g.nested[i] = true, g.parent[p] = true;
            continue;
        }
        const auto after = j.find("after");
        if (after == j.end() || !after->is_array()) fail(where + ": after must be an array of job names");
        dependencies += after->size();
        if (dependencies > kMaxDependencies)
            fail(fmt::format("otherData.jobs: more than {} dependencies", kMaxDependencies));
        for (const json& d : *after) {
            if (!d.is_string()) fail(where + ": after must be an array of job names");
            g.after[i].push_back(job_named(d.get<std::string>(), where + ": after"));
        }
    }
    // Kahn's order over the top-level jobs; what is left holds a cycle.
    std::vector<std::size_t> waiting(g.jobs, 0);
    std::vector<std::vector<std::size_t>> before(g.jobs);
    for (std::size_t i = 0; i < g.jobs; ++i) {
        if (g.nested[i]) continue;
        for (const std::size_t d : g.after[i]) {
            if (g.nested[d])
                fail(fmt::format("otherData.jobs: '{}' runs after '{}', a nested job", g.names[i],
                                 g.names[d]));
            ++waiting[i], before[d].push_back(i);
        }
    }
    for (std::size_t i = 0; i < g.jobs; ++i)
        if (!g.nested[i] && waiting[i] == 0) g.topological.push_back(i);
    for (std::size_t k = 0; k < g.topological.size(); ++k)
        for (const std::size_t next : before[g.topological[k]])
            if (--waiting[next] == 0) g.topological.push_back(next);
    for (std::size_t i = 0; i < g.jobs; ++i)
        if (!g.nested[i] && waiting[i] > 0)
            fail(fmt::format("otherData.jobs: the jobs form a cycle through '{}' (a job runs after itself)",
                             g.names[i]));
    return g;
}

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const auto i = static_cast<std::size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
    return v[std::min(i, v.size() - 1)];
}

// Longest chain of job spans through the graph for one frame; `spans` is indexed by job. The chain ends
// at the first job (file order) of greatest length; each job continues its first longest predecessor.
std::pair<double, std::vector<std::string>> critical_path(const Graph& g, const std::vector<Span>& spans,
                                                          std::vector<double>& longest,
                                                          std::vector<std::size_t>& via) {
    constexpr std::size_t kNone = ~std::size_t{0};
    for (const std::size_t j : g.topological) {
        double before = 0;
        via[j] = kNone;
        for (const std::size_t d : g.after[j]) {
            if (longest[d] > before || via[j] == kNone) {
                before = std::max(before, longest[d]);
                via[j] = d;
            }
        }
        longest[j] = before + spans[j].length();
    }
    std::size_t end = kNone;
    double length = -1;
    for (std::size_t j = 0; j < g.jobs; ++j)
        if (!g.nested[j] && longest[j] > length) length = longest[j], end = j;
    std::vector<std::string> path;
    for (std::size_t at = end; at != kNone; at = via[at]) path.push_back(g.names[at]);
    std::reverse(path.begin(), path.end());
    return {std::max(length, 0.0), path};
}

}  // namespace

TraceSummary summarize_trace(const nlohmann::json& trace) {
    if (!trace.is_object() || !trace.contains("traceEvents") || !trace["traceEvents"].is_array())
        fail("not a Chrome trace: no traceEvents array");
    const auto other = trace.find("otherData");
    if (other == trace.end() || !other->is_object() || !other->contains("jobs"))
        fail("not a Rivulet capture: otherData.jobs (the frame graph) is missing");
    Graph g = read_graph(other->at("jobs"));

    std::vector<Zone> zones;
    std::map<int, std::string> thread_names;
    const json& events = trace["traceEvents"];
    for (std::size_t i = 0; i < events.size(); ++i) {
        const json& e = events[i];
        const std::string where = fmt::format("traceEvents[{}]", i);
        if (!e.is_object()) fail(where + " must be an object");
        const auto ph = e.find("ph");
        if (ph == e.end() || !ph->is_string()) continue;
        const auto tid_of = [&] {
            const auto t = e.find("tid");
            return t == e.end() ? 0 : static_cast<int>(integer_in(*t, 0, kMaxTid, where + ".tid"));
        };
        if (*ph == "M" && e.value("name", json()) == "thread_name") {
            const auto args = e.find("args");
            if (args == e.end() || !args->is_object()) fail(where + ".args must be an object");
            thread_names[tid_of()] = string_at(*args, "name", where + ".args");
        }
        if (*ph != "X") continue;
        Zone z;
        z.name = g.intern(string_at(e, "name", where));
        if (g.names.size() > kMaxJobs + 65536) fail("the trace names more than 65536 kinds of zone");
        z.tid = tid_of();
        if (const auto args = e.find("args"); args != e.end()) {
            if (!args->is_object()) fail(where + ".args must be an object");
            if (const auto f = args->find("frame"); f != args->end())
                z.frame = integer_in(*f, 0, kMaxFrame, where + ".args.frame");
        }
        const auto ts = e.find("ts"), dur = e.find("dur");
        if (ts == e.end() || dur == e.end()) fail(where + ": a complete event needs ts and dur");
        z.begin = time_in(*ts, -kMaxMicroseconds, where + ".ts");
        z.end = z.begin + time_in(*dur, 0, where + ".dur");
        zones.push_back(z);
    }
    if (zones.empty()) fail("the trace holds no zones");

    TraceSummary s;
    // Per zone name: top-level jobs in file order, then nested jobs, then the zones outside the graph
    // (render, png_encode).
    std::vector<std::vector<double>> durations(g.names.size());
    for (const Zone& z : zones) durations[z.name].push_back((z.end - z.begin) * 1e-3);
    std::vector<std::size_t> order;
    for (std::size_t j = 0; j < g.jobs; ++j)
        if (!g.nested[j]) order.push_back(j);
    for (std::size_t j = 0; j < g.jobs; ++j)
        if (g.nested[j]) order.push_back(j);
    for (std::size_t n = g.jobs; n < g.names.size(); ++n) order.push_back(n);
    for (const std::size_t n : order) {
        std::vector<double>& d = durations[n];
        if (d.empty()) continue;
        JobStats js{g.names[n], d.size(), 0, 0, *std::max_element(d.begin(), d.end()), 0};
        for (double v : d) js.total_ms += v;
        js.p95_ms = percentile(d, 0.95);
        js.median_ms = percentile(std::move(d), 0.5);
        s.jobs.push_back(js);
    }

    // Wall, busy, idle per thread. Nested jobs run inside their parent's zone: their zones (not the
    // parent's) count as busy time, so no work is counted twice.
    // The render's passes (render.*, and the screen-space pass's screen.* outside the graph) lie inside
    // its zone: the render counts, not they.
    const auto inside_render = [&g](std::size_t name) {
        const std::string& n = g.names[name];
        return name >= g.jobs && (n.rfind("render.", 0) == 0 || n.rfind("screen.", 0) == 0);
    };
    double first = 1e300, last = -1e300;
    std::map<int, double> busy;
    for (const Zone& z : zones) {
        first = std::min(first, z.begin), last = std::max(last, z.end);
        if ((z.name >= g.jobs && !inside_render(z.name)) || (z.name < g.jobs && !g.parent[z.name]))
            busy[z.tid] += z.end - z.begin;
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
    const std::size_t render_name = g.intern("render");
    std::vector<std::size_t> by_frame(zones.size());
    std::iota(by_frame.begin(), by_frame.end(), std::size_t{0});
    std::stable_sort(by_frame.begin(), by_frame.end(),
                     [&zones](std::size_t a, std::size_t b) { return zones[a].frame < zones[b].frame; });
    std::size_t frames_with_jobs = 0;
    for (std::size_t k = 0; k < by_frame.size(); ++k)
        if ((k == 0 || zones[by_frame[k]].frame != zones[by_frame[k - 1]].frame)) ++frames_with_jobs;
    if (double(frames_with_jobs) * double(std::max<std::size_t>(g.jobs, 1)) > kMaxPathWork)
        fail(fmt::format("the trace has {} frames of a {}-job graph: too large to summarize",
                         frames_with_jobs, g.jobs));

    std::map<std::int64_t, Span> extraction, render;
    std::vector<Span> spans(g.jobs);
    std::vector<double> longest(g.jobs);
    std::vector<std::size_t> via(g.jobs);
    std::vector<std::pair<double, std::size_t>> lengths;  // (length, first zone of the frame in by_frame)
    const auto frame_spans = [&](std::size_t k) {
        std::fill(spans.begin(), spans.end(), Span{});
        const std::int64_t frame = zones[by_frame[k]].frame;
        for (; k < by_frame.size() && zones[by_frame[k]].frame == frame; ++k) {
            const Zone& z = zones[by_frame[k]];
            if (z.name < g.jobs) spans[z.name].add(z.begin, z.end);
        }
        return k;
    };
    for (std::size_t k = 0; k < by_frame.size();) {
        const std::size_t begin = k;
        bool any = false;
        for (std::size_t i = k; i < by_frame.size() && zones[by_frame[i]].frame == zones[by_frame[k]].frame;
             ++i) {
            const Zone& z = zones[by_frame[i]];
            if (z.name == render_name) {
                render[z.frame].add(z.begin, z.end);
            } else if (z.name < g.jobs) {  // not render's passes, PNG or video encoding
                extraction[z.frame].add(z.begin, z.end);
                any = true;
            }
        }
        k = frame_spans(begin);
        if (any) lengths.emplace_back(critical_path(g, spans, longest, via).first, begin);
    }
    std::stable_sort(lengths.begin(), lengths.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    if (!lengths.empty()) {
        frame_spans(lengths[lengths.size() / 2].second);
        const auto [length, path] = critical_path(g, spans, longest, via);
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
    s.frames = static_cast<int>(std::max(extraction.size(), render.size()));
    return s;
}

TraceSummary summarize_trace_file(const std::string& path) {
    const nlohmann::json doc = io::read_json_file(path, io::kMaxTraceFileBytes, "traces");
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
