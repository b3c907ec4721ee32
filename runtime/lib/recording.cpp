#include "runtime/lib/recording.h"

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "jobs/mesh_hash.h"
#include "systems/io/file_format_error.h"
#include "systems/io/io_limits.h"
#include "systems/io/json_file.h"
#include "systems/io/output_file.h"
#include "systems/render/screen_fluid_json.h"
#include "systems/scan/scan_settings_json.h"
#include "systems/scenes/scene_json.h"
#include "systems/scenes/scene_limits.h"
#include "systems/slices/slices_settings_json.h"
#include "systems/volume/volume_settings_json.h"

namespace rivulet {
namespace {

using nlohmann::json;

std::string checksum_of(const json& body) {
    const std::string text = body.dump();
    return hash_hex(hash_bytes(text.data(), text.size()));
}

std::uint64_t parse_hash(const json& j, const std::string& where) {
    if (!j.is_string() || j.get<std::string>().size() != 16)
        throw RecordingError(where + ": expected 16 hex digits");
    const std::string s = j.get<std::string>();
    char* end = nullptr;
    const std::uint64_t v = std::strtoull(s.c_str(), &end, 16);
    if (end != s.c_str() + s.size()) throw RecordingError(where + ": expected 16 hex digits");
    return v;
}

float parse_float(const json& j, const std::string& where) {
    if (!j.is_number() || !std::isfinite(j.get<double>()))
        throw RecordingError(where + ": expected a number");
    return j.get<float>();
}

}  // namespace

void write_recording(const std::string& path, const Recording& r) {
    json doc;
    doc["format"] = kRecordingFormat;
    doc["version"] = kRecordingVersion;
    doc["scene"] = scene_to_json(r.scene);
    doc["method"] = surface_method_name(r.method);
    doc["settings"] = r.method == SurfaceMethod::kScan     ? scan_settings_to_json(r.scan)
                      : r.method == SurfaceMethod::kSlices ? slices_settings_to_json(r.slices)
                      : r.method == SurfaceMethod::kVolume ? volume_settings_to_json(r.volume)
                                                           : screen_fluid_settings_to_json(r.screen);
    json inputs = json::array();
    for (const FrameInputs& in : r.inputs)
        inputs.push_back(
            {in.container_offset.x, in.container_offset.y, in.container_offset.z, in.emitter_scale});
    doc["inputs"] = std::move(inputs);
    json frames = json::array();
    for (const RecordedFrame& f : r.frames) frames.push_back({hash_hex(f.particles), hash_hex(f.surface)});
    doc["frames"] = std::move(frames);
    doc["checksum"] = checksum_of(doc);
    try {
        io::write_text_file(path, doc.dump(1) + "\n");
    } catch (const FileFormatError& e) {
        throw RecordingError(std::string("cannot write recording: ") + e.what());
    }
}

Recording read_recording(const std::string& path) {
    const std::string where = "recording '" + path + "'";
    json doc;
    try {
        doc = io::read_json_file(path, io::kMaxRecordingBytes, "recordings");
    } catch (const FileFormatError& e) {
        throw RecordingError(std::string("cannot read recording: ") + e.what());
    }
    if (!doc.is_object()) throw RecordingError(where + " is not a Rivulet recording (not one JSON object)");
    if (doc.value("format", json()) != kRecordingFormat)
        throw RecordingError(where + " is not a Rivulet recording (format is not \"" +
                             std::string(kRecordingFormat) + "\")");
    const json version = doc.value("version", json());
    if (version != kRecordingVersion)
        throw RecordingError(where + " has version " + version.dump() + "; this build reads version " +
                             std::to_string(kRecordingVersion));
    const auto sum = doc.find("checksum");
    if (sum == doc.end() || !sum->is_string()) throw RecordingError(where + " has no checksum");
    const std::string expected = sum->get<std::string>();
    doc.erase("checksum");
    if (checksum_of(doc) != expected)
        throw RecordingError(where + " is damaged: its checksum does not match its content");

    Recording r;
    try {
        r.scene = scene_from_json(doc.at("scene"), where + ": scene");
        r.method = parse_surface_method(doc.at("method").get<std::string>());
        if (r.method == SurfaceMethod::kScan) {
            // Recordings from before the path axis existed were made with V-axis cylinders.
            nlohmann::json settings = doc.at("settings");
            if (settings.is_object() && !settings.contains("axis")) settings["axis"] = "vertical";
            r.scan = scan_settings_from_json(settings, where + ": settings");
        } else if (r.method == SurfaceMethod::kSlices) {
            r.slices = slices_settings_from_json(doc.at("settings"), where + ": settings");
        } else if (r.method == SurfaceMethod::kVolume) {
            r.volume = volume_settings_from_json(doc.at("settings"), where + ": settings");
        } else {
            r.screen = screen_fluid_settings_from_json(doc.at("settings"), where + ": settings");
        }
        const json& inputs = doc.at("inputs");
        const json& frames = doc.at("frames");
        if (!inputs.is_array() || !frames.is_array() || frames.size() > std::size_t(kMaxRunFrames))
            throw RecordingError(where + ": inputs and frames must be arrays, frames at most " +
                                 std::to_string(kMaxRunFrames));
        if (inputs.size() != std::size_t(r.scene.warmup_frames) + frames.size())
            throw RecordingError(where + ": expected one input per simulated frame (" +
                                 std::to_string(std::size_t(r.scene.warmup_frames) + frames.size()) +
                                 "), found " + std::to_string(inputs.size()));
        for (std::size_t i = 0; i < inputs.size(); ++i) {
            const json& e = inputs[i];
            const std::string at = where + ": inputs[" + std::to_string(i) + "]";
            if (!e.is_array() || e.size() != 4)
                throw RecordingError(at + ": expected [ox, oy, oz, emitter_scale]");
            r.inputs.push_back({{parse_float(e[0], at), parse_float(e[1], at), parse_float(e[2], at)},
                                parse_float(e[3], at)});
        }
        for (std::size_t i = 0; i < frames.size(); ++i) {
            const json& e = frames[i];
            const std::string at = where + ": frames[" + std::to_string(i) + "]";
            if (!e.is_array() || e.size() != 2) throw RecordingError(at + ": expected [particles, surface]");
            r.frames.push_back({parse_hash(e[0], at), parse_hash(e[1], at)});
        }
    } catch (const RecordingError&) {
        throw;
    } catch (const std::exception& e) {
        throw RecordingError(where + ": " + e.what());
    }
    if (r.frames.empty()) throw RecordingError(where + " records no frames");
    return r;
}

Recording make_recording(const FramePipeline& pipeline, std::span<const FrameInputs> inputs) {
    Recording r;
    r.scene = pipeline.scene();
    r.method = pipeline.config().method;
    r.scan = pipeline.config().scan;
    r.slices = pipeline.config().slices;
    r.screen = pipeline.config().screen;
    r.volume = pipeline.config().volume;
    r.inputs.assign(inputs.begin(), inputs.end());
    for (const FrameRecord& f : pipeline.records()) r.frames.push_back({f.particle_hash, f.hash});
    return r;
}

std::optional<Divergence> first_divergence(std::span<const RecordedFrame> recorded,
                                           std::span<const FrameRecord> replayed) {
    const std::size_t n = std::min(recorded.size(), replayed.size());
    for (std::size_t i = 0; i < n; ++i) {
        const RecordedFrame& want = recorded[i];
        const FrameRecord& got = replayed[i];
        if (want.particles != got.particle_hash)
            return Divergence{i, got.frame, "particles", want.particles, got.particle_hash};
        if (want.surface != got.hash) return Divergence{i, got.frame, "surface", want.surface, got.hash};
    }
    if (replayed.size() != recorded.size())
        return Divergence{n, 0, "frame count", recorded.size(), replayed.size()};
    return std::nullopt;
}

ReplayOutcome replay_recording(const Recording& rec, std::size_t frames,
                               const std::function<void(int)>& on_frame) {
    const std::span<const RecordedFrame> recorded =
        std::span(rec.frames).first(frames > 0 ? std::min(frames, rec.frames.size()) : rec.frames.size());
    PipelineSettings config;
    config.method = rec.method;
    config.scan = rec.scan;
    config.slices = rec.slices;
    config.volume = rec.volume;
    config.screen = rec.screen;
    config.render = false;  // hashes cover the particles and the surface; pictures add nothing to compare
    config.hash_frames = true;
    config.inputs = [&rec](std::uint64_t f) { return f < rec.inputs.size() ? rec.inputs[f] : FrameInputs{}; };
    FramePipeline pipeline(rec.scene, config);
    pipeline.warmup();
    pipeline.reserve_records(recorded.size());
    pipeline.run(static_cast<int>(recorded.size()), on_frame);
    return {recorded.size(), first_divergence(recorded, pipeline.records())};
}

}  // namespace rivulet
