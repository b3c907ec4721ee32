#pragma once
// Each subcommand of `rivulet` registers itself on the CLI11 app; the callback runs the command and
// leaves its exit status in `status`.
#include <CLI/CLI.hpp>
#include <nlohmann/json_fwd.hpp>
#include <string>

#include "systems/render/screen_fluid.h"
#include "systems/scan/scan_settings.h"
#include "systems/scenes/scene.h"
#include "systems/slices/slices_settings.h"
#include "systems/volume/volume_settings.h"

namespace rivulet::cli {

void add_run_command(CLI::App& app, int& status);
void add_mesh_command(CLI::App& app, int& status);
void add_trace_summary_command(CLI::App& app, int& status);
void add_replay_command(CLI::App& app, int& status);
void add_simulate_command(CLI::App& app, int& status);
void add_bench_command(CLI::App& app, int& status);

// Options of sphere scan conversion shared by `run` and `mesh` (--u, --v, --epsilon, ...).
struct ScanOptions {
    ScanSettings settings;
    std::string radial = "maxima";
    std::string axis = "path";
    void add_to(CLI::App& cmd);
    // Applies --radial; throws std::invalid_argument on a bad value.
    ScanSettings resolve() const;
};

// The options every extracting command shares, each with its check: --method (scan or slices, and
// screen where frames are rendered) and --threads (0 = all hardware threads, at most 1024).
void add_method_option(CLI::App& cmd, std::string& method, bool rendered);
// The method a rendered command uses: `given`, or when empty scan (sprites for a diffuse scene).
std::string default_method(const std::string& given, const SceneDesc& scene);
void add_threads_option(CLI::App& cmd, int& threads, const std::string& help);

// The scene options `run` and `simulate` share: --scene (built-in name or FILE.json), --frames in
// [1, 1000000], --warmup (simulated frames before frame 0; default the scene's).
struct SceneOptions {
    std::string name = "fountain";
    int frames = 120;
    int warmup = -1;
    void add_to(CLI::App& cmd, const std::string& frames_help);
    // The scene with --warmup applied; throws on an unknown name or a bad scene file.
    SceneDesc resolve() const;
};

// Options of marching slices shared by `run` and `mesh` (--voxel, --block, --exhaustive-seeds).
struct SlicesOptions {
    float voxel = 0;
    std::string field = "spacing";
    float spacing = 0;
    std::uint32_t block = SlicesSettings{}.block_cubes;
    bool exhaustive = false;
    float anisotropy = 0;  // --anisotropic: the longest kernel axis over the shortest; 0: spheres
    float anisotropy_smoothing = SlicesSettings{}.anisotropy_smoothing;
    void add_to(CLI::App& cmd);
    // Copies the options into `s` (radius and limits untouched).
    void apply(SlicesSettings& s) const;
};

// Options of the density volume shared by `run` and `mesh` (--kernel, --max-dim, --iso; --level-set for
// `mesh`). Its voxel is --voxel (SlicesOptions).
struct VolumeOptions {
    VolumeSettings settings;
    bool level_set = false;
    void add_to(CLI::App& cmd, bool offline);
    // The settings with `voxel` (--voxel, 0: automatic); the radius is set by the caller.
    VolumeSettings resolve(float voxel) const;
};

// Options of the screen-space fluid method (--depth-filter, --filter-iterations, --filter-radius); checked
// when the pipeline is built.
struct ScreenOptions {
    ScreenFluidSettings settings;
    bool iterations_given = false;
    void add_to(CLI::App& cmd);
};

// Writes `doc` pretty-printed to `path`; throws std::runtime_error when the file cannot be written.
void write_json_file(const std::string& path, const nlohmann::json& doc);

// Parses "WxH" (e.g. 1280x720); throws std::invalid_argument with a clear message.
void parse_size(const std::string& text, int& width, int& height);

}  // namespace rivulet::cli
