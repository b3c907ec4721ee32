// Input tracks (`run --inputs`): text keys. An accepted track has increasing frames and finite inputs
// within its limits at every frame asked, between and beyond its keys.
#include <cmath>

#include "systems/scenes/input_track.h"
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("input.txt", data, size);
    const auto track = rivulet::fuzz::read_or_reject([&] { return rivulet::read_input_track(path); });
    if (!track) return 0;
    if (track->keys.empty()) rivulet::fuzz::finding("an accepted track holds no keys");
    for (std::size_t k = 1; k < track->keys.size(); ++k)
        if (track->keys[k].frame <= track->keys[k - 1].frame)
            rivulet::fuzz::finding("frames do not increase");
    for (const rivulet::InputKey& key : track->keys) {
        for (const std::uint64_t f : {key.frame, key.frame + 1, key.frame / 2}) {
            const rivulet::FrameInputs in = track->at(f);
            const rivulet::Vec3f o = in.container_offset;
            if (!(std::abs(o.x) <= 1000.0f && std::abs(o.y) <= 1000.0f && std::abs(o.z) <= 1000.0f) ||
                !(in.emitter_scale >= 0.0f && in.emitter_scale <= 1000.0f))
                rivulet::fuzz::finding("an input out of its limits");
        }
    }
    return 0;
}
