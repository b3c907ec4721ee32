#include "rivulet/recording.h"

#include "runtime/api/api_support.h"
#include "runtime/lib/recording.h"
#include "runtime/lib/surface_system.h"
#include "systems/scenes/scene_limits.h"

namespace rivulet {

ReplayReport replay(const std::string& path, int frames, int threads) {
    return api::translate_errors([&] {
        if (frames < 0 || frames > kMaxRunFrames)
            throw Error("frames must be between 0 (all) and " + std::to_string(kMaxRunFrames) + ", got " +
                        std::to_string(frames));
        api::WorkerArena arena;
        tbb::task_arena& workers = arena.get(threads);
        const Recording rec = read_recording(path);
        ReplayReport report;
        report.scene = rec.scene.name;
        report.method = surface_method_name(rec.method);
        report.recorded = rec.frames.size();
        ReplayOutcome outcome;
        workers.execute([&] { outcome = replay_recording(rec, std::size_t(frames)); });
        report.frames = outcome.frames;
        if (const auto& d = outcome.divergence) {
            report.identical = false;
            report.frame = d->frame;
            report.simulation_frame = d->sim_frame;
            report.buffer = d->buffer;
            report.recorded_hash = d->recorded;
            report.replayed_hash = d->replayed;
        }
        return report;
    });
}

}  // namespace rivulet
