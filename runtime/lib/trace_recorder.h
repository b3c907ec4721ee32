#pragma once
// Trace capture: every job (and every item of a parallel job) runs in a zone, recorded into per-thread
// buffers sized up front, without locks: a thread only ever appends to the buffer of its TBB arena slot
// (the render thread is slot 0). Off, a zone costs one pointer test in the caller. A full buffer drops
// further zones and counts them; it never grows during a run.
#include <chrono>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

namespace rivulet {

struct TraceZone {
    std::int64_t begin_ns = 0, end_ns = 0;  // since the recorder's epoch
    std::uint32_t frame = 0;
    std::int32_t item = -1;  // group, bin or chunk of a parallel job; -1 for a whole job
    std::uint16_t name = 0;
    std::uint16_t thread = 0;
};

class TraceRecorder {
  public:
    TraceRecorder(std::size_t threads, std::size_t zones_per_thread);

    // Setup only (allocates): the id of a zone name.
    std::uint16_t intern(const std::string& name);
    const std::vector<std::string>& names() const { return names_; }

    std::int64_t now_ns() const {
        return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - epoch_)
            .count();
    }
    // Appends to the calling thread's buffer.
    void record(std::uint16_t name, std::uint32_t frame, std::int32_t item, std::int64_t begin_ns,
                std::int64_t end_ns);

    std::size_t threads() const { return buffers_.size(); }
    std::size_t dropped() const;
    // All zones of all threads ordered by start time (after the run; allocates).
    std::vector<TraceZone> zones() const;

  private:
    struct alignas(64) Buffer {
        std::vector<TraceZone> zones;
        std::size_t count = 0, dropped = 0;
    };
    std::chrono::steady_clock::time_point epoch_;
    std::vector<std::string> names_;
    std::vector<Buffer> buffers_;
};

class FrameGraph;

// Chrome Trace Event Format (opens in Perfetto UI and chrome://tracing): one "X" event per zone with
// frame and item in args, thread names, a global instant event per rendered frame, and a flow arrow
// from each frame's upload_staging (end of its extraction) to its render. The frame graph's jobs and
// dependencies go into otherData.jobs, for trace summaries.
nlohmann::json chrome_trace(const TraceRecorder& recorder, const FrameGraph& graph);
void write_chrome_trace(const std::string& path, const nlohmann::json& trace);

}  // namespace rivulet
