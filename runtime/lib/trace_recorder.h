#pragma once
// Trace capture: every job (and every item of a parallel job) runs in a zone, recorded into per-thread
// buffers without locks: a thread only ever appends to the buffer of its TBB arena slot (the render
// thread is slot 0). Off, a zone costs one pointer test in the caller. A buffer grows by chunks of
// kTraceChunkZones as zones arrive (one allocation per chunk, none per zone), so memory follows what is
// recorded, not the run's length; all threads together keep at most `max_zones`, and zones beyond it
// are dropped and counted.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
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

inline constexpr std::size_t kTraceChunkZones = 4096;                // 128 KiB
inline constexpr std::size_t kMaxTraceZones = std::size_t{1} << 20;  // 32 MiB of zones, ~200 MB of JSON

class TraceRecorder {
  public:
    // Allocates only the chunk tables (a pointer per chunk that max_zones can need, per thread).
    explicit TraceRecorder(std::size_t threads, std::size_t max_zones = kMaxTraceZones);

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
    std::size_t max_zones() const { return max_zones_; }
    // Zones a thread claims at a time: kTraceChunkZones, less where a small cap must leave every thread
    // some (a quarter of its share).
    std::size_t chunk_zones() const { return chunk_zones_; }
    // Zones the chunks allocated so far can hold (all threads).
    std::size_t allocated_zones() const { return max_zones_ - zones_left_.load(std::memory_order_relaxed); }
    std::size_t dropped() const;
    // All zones of all threads ordered by start time (after the run; allocates).
    std::vector<TraceZone> zones() const;

  private:
    struct Chunk {
        std::unique_ptr<TraceZone[]> zones;
        std::size_t capacity = 0, count = 0;
    };
    struct alignas(64) Buffer {
        std::vector<Chunk> chunks;  // reserved up front: appending never reallocates the table
        std::size_t dropped = 0;
    };
    // A new chunk for `b`, up to kTraceChunkZones from the zones left to all threads; false when none are.
    bool grow(Buffer& b);

    std::chrono::steady_clock::time_point epoch_;
    std::vector<std::string> names_;
    std::size_t max_zones_;
    std::size_t chunk_zones_;
    std::atomic<std::size_t> zones_left_;
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
