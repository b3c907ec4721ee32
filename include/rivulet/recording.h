#pragma once
// Recordings (docs/recording.md): `rivulet run --record FILE` writes what reproduces a run (scene, surface
// method and settings, every frame's outside inputs) and every frame's particle and surface hashes.
// replay() re-runs one in your program, as `rivulet replay` does, and reports the first frame that
// differs: a determinism check for a build, a machine or a thread count.
//
//   rivulet::ReplayReport r = rivulet::replay("run.rivrec", 30);   // the first 30 recorded frames
//   if (!r.identical) std::printf("frame %zu: %s differs\n", r.frame, r.buffer.c_str());
//
// Errors (a missing, damaged or foreign file; bad arguments) throw rivulet::Error (<rivulet/error.h>).
#include <cstddef>
#include <cstdint>
#include <string>

namespace rivulet {

struct ReplayReport {
    std::string scene;         // the recorded scene's name
    std::string method;        // the surface method, as `--method` names it
    std::size_t recorded = 0;  // recorded frames in the file
    std::size_t frames = 0;    // recorded frames replayed
    bool identical = true;
    // When not identical: the first recorded frame that differs (0 = the first after warm-up), its
    // simulation frame (warm-up frames counted), what differs ("particles", "surface" or "frame count")
    // and the recorded and replayed hashes (or frame counts).
    std::size_t frame = 0;
    std::uint64_t simulation_frame = 0;
    std::string buffer;
    std::uint64_t recorded_hash = 0, replayed_hash = 0;
};

// Replays the file's first `frames` recorded frames (0: all) on `threads` workers (0: every hardware
// thread; the result does not depend on it).
ReplayReport replay(const std::string& path, int frames = 0, int threads = 0);

}  // namespace rivulet
