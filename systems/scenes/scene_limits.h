#pragma once
// The limits every scene and run obeys, whether a value comes from the command line, a scene file or a
// recording (docs/limits.md): each is far above any useful run and keeps a typo from asking for hours of
// work or gigabytes of memory before the first frame.
#include <cstdint>

namespace rivulet {

inline constexpr int kMaxRunFrames = 1'000'000;     // --frames, frames of a recording
inline constexpr int kMaxWarmupFrames = 1'000'000;  // --warmup, warmup_frames of a scene
inline constexpr std::uint32_t kMaxSceneParticles = 50'000'000;
inline constexpr int kMaxPoolSamples = 1024;  // pool nx and nz
// Buffers a simulation allocates up front (particles, SPH grid): refused beyond this.
inline constexpr std::uint64_t kMaxSimulationBytes = std::uint64_t{8} << 30;

}  // namespace rivulet
