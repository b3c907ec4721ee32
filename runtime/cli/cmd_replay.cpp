// rivulet replay: re-run a recording and report the first frame and buffer that differ (exit 1).
#include <fmt/format.h>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "jobs/mesh_hash.h"
#include "runtime/lib/recording.h"
#include "runtime/lib/thread_control.h"
#include "systems/scenes/scene_limits.h"

namespace rivulet::cli {
namespace {

struct ReplayOptions {
    std::string file;
    int threads = 0;
    int frames = 0;  // the first this many recorded frames; 0: all
};

int replay(const ReplayOptions& o) {
    const Recording rec = read_recording(o.file);
    const std::size_t recorded = rec.frames.size();
    ThreadControl threads(o.threads);
    const int frames =
        o.frames > 0 && std::size_t(o.frames) < recorded ? o.frames : static_cast<int>(recorded);
    ProgressBar bar("replay", frames);
    const ReplayOutcome outcome =
        replay_recording(rec, std::size_t(frames), [&bar](int i) { bar.update(i + 1); });

    const auto& diverged = outcome.divergence;
    if (!diverged) {
        fmt::print("replay {}: scene {}, method {}, {} of {} frames at {} threads: identical\n", o.file,
                   rec.scene.name, surface_method_name(rec.method), frames, recorded, threads.threads());
        return 0;
    }
    const Divergence& d = *diverged;
    fmt::print(
        "replay {}: scene {}, method {}, {} threads: DIVERGED at frame {} (simulation frame {}): {} "
        "recorded {} replayed {}\n",
        o.file, rec.scene.name, surface_method_name(rec.method), threads.threads(), d.frame, d.sim_frame,
        d.buffer, hash_hex(d.recorded), hash_hex(d.replayed));
    return 1;
}

}  // namespace

void add_replay_command(CLI::App& app, int& status) {
    auto opts = std::make_shared<ReplayOptions>();
    CLI::App* cmd = app.add_subcommand(
        "replay",
        "Re-run a recording (rivulet run --record) and report the first frame that differs (exit 1)");
    cmd->add_option("FILE", opts->file, "Recording file")->required();
    add_threads_option(*cmd, opts->threads, "Threads for TBB (0 = all)");
    cmd->add_option("--frames", opts->frames, "Replay only the first N recorded frames (0 = all)")
        ->check(CLI::Range(0, kMaxRunFrames));
    cmd->callback([opts, &status] { status = replay(*opts); });
}

}  // namespace rivulet::cli
