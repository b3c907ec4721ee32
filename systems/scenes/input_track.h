#pragma once
// An input track: a run's outside inputs (FrameInputs) read from a text file instead of the scene's
// script, e.g. a user's tank motion captured elsewhere (`rivulet run --inputs`). One key per line:
//   frame  dx dy dz  [emitter_scale]
// frame: simulated frame (warm-up included, as recordings count), strictly increasing; dx dy dz: the
// container's offset in m; emitter_scale: default 1. Between keys the inputs are interpolated linearly;
// before the first key they are the first key's, after the last the last key's. '#' starts a comment
// that runs to the end of the line. A recording made with a track stores each frame's inputs, so replay needs
// no track.
#include <cstdint>
#include <string>
#include <vector>

#include "systems/scenes/frame_inputs.h"

namespace rivulet {

struct InputKey {
    std::uint64_t frame = 0;
    FrameInputs inputs;
};

struct InputTrack {
    std::vector<InputKey> keys;  // at least one, frames strictly increasing
    // The inputs of simulated frame `frame`; allocates nothing.
    FrameInputs at(std::uint64_t frame) const;
};

// Limits: at most kMaxInputKeys keys and frames below 2^40; offsets within 1000 m, emitter scales in
// [0, 1000], every value finite. Anything else is an io::FileFormatError naming the line.
inline constexpr std::size_t kMaxInputKeys = 10'000'000;
InputTrack read_input_track(const std::string& path);

}  // namespace rivulet
