#pragma once
// Recordings (docs/recording.md): what reproduces a run — scene, surface method and its settings, the
// outside inputs of every simulated frame — and what the run produced: per frame, the hash of the
// particle arrays and of the surface buffers. `rivulet replay` re-runs a recording and names the first
// frame and buffer that differ.
#include <cstdint>
#include <functional>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/lib/frame_pipeline.h"
#include "systems/scan/scan_settings.h"
#include "systems/scenes/frame_inputs.h"
#include "systems/scenes/scene.h"

namespace rivulet {

inline constexpr const char* kRecordingFormat = "rivulet-recording";
inline constexpr int kRecordingVersion = 1;

struct RecordedFrame {
    std::uint64_t particles = 0;  // particle_hash of the set the surface was extracted from
    std::uint64_t surface = 0;    // hash of the surface buffers of the frame
};

struct Recording {
    SceneDesc scene;  // warm-up frames included (scene.warmup_frames)
    SurfaceMethod method = SurfaceMethod::kScan;
    ScanSettings scan;  // settings of the method recorded (the others keep their defaults)
    SlicesSettings slices;
    ScreenFluidSettings screen;
    VolumeSettings volume;
    std::vector<FrameInputs> inputs;    // every simulated frame: warm-up frames first, then recorded ones
    std::vector<RecordedFrame> frames;  // recorded frames (after warm-up)
};

// A file that is not a recording, of another version, damaged (checksum) or inconsistent.
struct RecordingError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Versioned JSON with an XXH3 checksum over the rest of the document; throws RecordingError on I/O.
void write_recording(const std::string& path, const Recording& recording);
Recording read_recording(const std::string& path);

// The recording of a finished run (records must carry hashes: config.hash_frames).
Recording make_recording(const FramePipeline& pipeline, std::span<const FrameInputs> inputs);

struct Divergence {
    std::size_t frame = 0;  // recorded frame index (0 = first after warm-up)
    std::uint64_t sim_frame = 0;
    std::string buffer;  // "particles" or "surface"
    std::uint64_t recorded = 0, replayed = 0;
};

// The first frame whose particle or surface hash differs (particles first: they are upstream).
std::optional<Divergence> first_divergence(std::span<const RecordedFrame> recorded,
                                           std::span<const FrameRecord> replayed);
inline std::optional<Divergence> first_divergence(const Recording& recording,
                                                  std::span<const FrameRecord> replayed) {
    return first_divergence(recording.frames, replayed);
}

struct ReplayOutcome {
    std::size_t frames = 0;  // recorded frames replayed
    std::optional<Divergence> divergence;
};

// Re-runs the recording's first `frames` recorded frames (0: all) without rendering, in the calling
// thread's TBB arena, and compares their hashes; `on_frame(i)` after replayed frame i. `rivulet replay`
// and rivulet::replay (include/rivulet/recording.h) both are this.
ReplayOutcome replay_recording(const Recording& recording, std::size_t frames,
                               const std::function<void(int)>& on_frame = {});

}  // namespace rivulet
