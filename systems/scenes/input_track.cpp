#include "systems/scenes/input_track.h"

#include <algorithm>
#include <cmath>

#include "systems/io/input_file.h"
#include "systems/io/line_fields.h"
#include "systems/io/text_parse.h"

namespace rivulet {

FrameInputs InputTrack::at(std::uint64_t frame) const {
    if (keys.empty()) return {};
    if (frame <= keys.front().frame) return keys.front().inputs;
    if (frame >= keys.back().frame) return keys.back().inputs;
    const auto next = std::upper_bound(keys.begin(), keys.end(), frame,
                                       [](std::uint64_t f, const InputKey& k) { return f < k.frame; });
    const InputKey& b = *next;
    const InputKey& a = *(next - 1);
    const float t = static_cast<float>(double(frame - a.frame) / double(b.frame - a.frame));
    FrameInputs in;
    in.container_offset =
        a.inputs.container_offset + (b.inputs.container_offset - a.inputs.container_offset) * t;
    in.emitter_scale = a.inputs.emitter_scale + (b.inputs.emitter_scale - a.inputs.emitter_scale) * t;
    return in;
}

InputTrack read_input_track(const std::string& path) {
    io::InputFile file(path);
    file.require_text_size("input track");
    io::LineFields lines(file);
    InputTrack track;
    const auto number = [&lines](std::string_view token, double lo, double hi, const char* what) {
        const std::optional<double> v = io::parse_double(token);
        if (!v || !std::isfinite(*v) || *v < lo || *v > hi)
            lines.fail(std::string(what) + " must be a number in [" + io::number_text(lo) + ", " +
                       io::number_text(hi) + "], got " + io::quoted(token));
        return *v;
    };
    while (lines.next()) {
        auto f = lines.fields();
        for (std::size_t k = 0; k < f.size(); ++k)
            if (f[k].front() == '#') f = f.first(k);  // a comment to the end of the line
        if (f.empty()) continue;
        if (f.size() != 4 && f.size() != 5)
            lines.fail("expected 'frame dx dy dz [emitter_scale]', got " + std::to_string(f.size()) +
                       " fields");
        const std::optional<std::uint64_t> frame = io::parse_uint64(f[0]);
        if (!frame || *frame >= (std::uint64_t{1} << 40))
            lines.fail("the frame must be a whole number below 2^40, got " + io::quoted(f[0]));
        if (!track.keys.empty() && *frame <= track.keys.back().frame)
            lines.fail("frames must increase: " + std::to_string(*frame) + " follows " +
                       std::to_string(track.keys.back().frame));
        if (track.keys.size() == kMaxInputKeys)
            lines.fail("more than " + std::to_string(kMaxInputKeys) + " keys");
        InputKey key;
        key.frame = *frame;
        key.inputs.container_offset = {static_cast<float>(number(f[1], -1000, 1000, "dx")),
                                       static_cast<float>(number(f[2], -1000, 1000, "dy")),
                                       static_cast<float>(number(f[3], -1000, 1000, "dz"))};
        if (f.size() == 5)
            key.inputs.emitter_scale = static_cast<float>(number(f[4], 0, 1000, "emitter_scale"));
        track.keys.push_back(key);
    }
    if (track.keys.empty()) file.fail("holds no keys (expected lines 'frame dx dy dz [emitter_scale]')");
    return track;
}

}  // namespace rivulet
