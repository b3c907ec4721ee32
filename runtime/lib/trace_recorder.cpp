#include "runtime/lib/trace_recorder.h"

#include "runtime/lib/frame_graph.h"
#include "systems/io/output_file.h"

#include <tbb/task_arena.h>
#include <algorithm>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace rivulet {

TraceRecorder::TraceRecorder(std::size_t threads, std::size_t max_zones)
    : epoch_(std::chrono::steady_clock::now()),
      max_zones_(max_zones),
      chunk_zones_(
          std::clamp<std::size_t>(max_zones / (4 * std::max<std::size_t>(threads, 1)), 1, kTraceChunkZones)),
      zones_left_(max_zones),
      buffers_(std::max<std::size_t>(threads, 1)) {
    // Chunks can come out short only at the very end of the budget, so one thread never needs more.
    const std::size_t chunks = (max_zones + chunk_zones_ - 1) / chunk_zones_ + 1;
    for (Buffer& b : buffers_) b.chunks.reserve(chunks);
}

bool TraceRecorder::grow(Buffer& b) {
    std::size_t left = zones_left_.load(std::memory_order_relaxed);
    std::size_t take = 0;
    do {
        take = std::min(left, chunk_zones_);
        if (take == 0) return false;
    } while (!zones_left_.compare_exchange_weak(left, left - take, std::memory_order_relaxed));
    b.chunks.push_back({std::make_unique_for_overwrite<TraceZone[]>(take), take, 0});
    return true;
}

std::uint16_t TraceRecorder::intern(const std::string& name) {
    const auto it = std::find(names_.begin(), names_.end(), name);
    if (it != names_.end()) return static_cast<std::uint16_t>(it - names_.begin());
    names_.push_back(name);
    return static_cast<std::uint16_t>(names_.size() - 1);
}

void TraceRecorder::record(std::uint16_t name, std::uint32_t frame, std::int32_t item, std::int64_t begin_ns,
                           std::int64_t end_ns) {
    // Outside any arena (before the first task ran) the index is negative: that is the main thread.
    const int slot = std::max(tbb::this_task_arena::current_thread_index(), 0);
    Buffer& b = buffers_[static_cast<std::size_t>(slot) % buffers_.size()];
    if ((b.chunks.empty() || b.chunks.back().count == b.chunks.back().capacity) && !grow(b)) {
        ++b.dropped;
        return;
    }
    Chunk& c = b.chunks.back();
    c.zones[c.count++] = {begin_ns, end_ns, frame, item, name, static_cast<std::uint16_t>(slot)};
}

std::size_t TraceRecorder::dropped() const {
    std::size_t n = 0;
    for (const Buffer& b : buffers_) n += b.dropped;
    return n;
}

std::vector<TraceZone> TraceRecorder::zones() const {
    std::vector<TraceZone> all;
    all.reserve(allocated_zones());
    for (const Buffer& b : buffers_)
        for (const Chunk& c : b.chunks) all.insert(all.end(), c.zones.get(), c.zones.get() + c.count);
    std::stable_sort(all.begin(), all.end(),
                     [](const TraceZone& a, const TraceZone& b) { return a.begin_ns < b.begin_ns; });
    return all;
}

nlohmann::json chrome_trace(const TraceRecorder& recorder, const FrameGraph& graph) {
    using nlohmann::json;
    json events = json::array();
    constexpr int kPid = 1;
    events.push_back({{"name", "process_name"}, {"ph", "M"}, {"pid", kPid}, {"args", {{"name", "rivulet"}}}});
    for (std::size_t t = 0; t < recorder.threads(); ++t) {
        const std::string name = t == 0 ? "main (render)" : "worker " + std::to_string(t);
        events.push_back(
            {{"name", "thread_name"}, {"ph", "M"}, {"pid", kPid}, {"tid", t}, {"args", {{"name", name}}}});
        events.push_back({{"name", "thread_sort_index"},
                          {"ph", "M"},
                          {"pid", kPid},
                          {"tid", t},
                          {"args", {{"sort_index", t}}}});
    }
    const auto& names = recorder.names();
    auto us = [](std::int64_t ns) { return static_cast<double>(ns) * 1e-3; };
    for (const TraceZone& z : recorder.zones()) {
        const std::string& name = names[z.name];
        json args = {{"frame", z.frame}};
        if (z.item >= 0) args["item"] = z.item;
        events.push_back({{"name", name},
                          {"cat", "job"},
                          {"ph", "X"},
                          {"pid", kPid},
                          {"tid", z.thread},
                          {"ts", us(z.begin_ns)},
                          {"dur", us(z.end_ns - z.begin_ns)},
                          {"args", args}});
        if (name == "upload_staging") {  // extraction of this frame is done: the arrow starts here
            events.push_back({{"name", "frame hand-over"},
                              {"cat", "frame"},
                              {"ph", "s"},
                              {"id", z.frame},
                              {"pid", kPid},
                              {"tid", z.thread},
                              {"ts", us(z.end_ns) - 0.001}});
        } else if (name == "render") {
            events.push_back({{"name", "frame hand-over"},
                              {"cat", "frame"},
                              {"ph", "f"},
                              {"bp", "e"},
                              {"id", z.frame},
                              {"pid", kPid},
                              {"tid", z.thread},
                              {"ts", us(z.begin_ns)}});
            events.push_back({{"name", "frame " + std::to_string(z.frame)},
                              {"cat", "frame"},
                              {"ph", "i"},
                              {"s", "g"},
                              {"pid", kPid},
                              {"tid", z.thread},
                              {"ts", us(z.begin_ns)}});
        }
    }
    json jobs = json::array();
    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
        json after = json::array();
        for (FrameGraph::JobId d : graph.job_after(j)) after.push_back(graph.job_name(d));
        json entry = {{"name", graph.job_name(j)}, {"after", after}};
        if (graph.job_parent(j) >= 0)
            entry["nested_in"] = graph.job_name(static_cast<FrameGraph::JobId>(graph.job_parent(j)));
        jobs.push_back(std::move(entry));
    }
    return json{{"traceEvents", events},
                {"displayTimeUnit", "ms"},
                {"otherData",
                 {{"format", "rivulet-trace-1"}, {"dropped_zones", recorder.dropped()}, {"jobs", jobs}}}};
}

void write_chrome_trace(const std::string& path, const nlohmann::json& trace) {
    io::write_text_file(path, trace.dump());
}

}  // namespace rivulet
