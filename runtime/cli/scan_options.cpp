#include <fmt/format.h>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "cli/commands.h"
#include "systems/io/output_file.h"
#include "systems/scenes/scene_json.h"
#include "systems/scenes/scene_limits.h"
#include "systems/scenes/scene_validation.h"

namespace rivulet::cli {
namespace {

// CLI11's PositiveNumber prints its range up to DBL_MAX in full; this says it plainly.
CLI::Validator positive_number() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            char* end = nullptr;
            const double v = std::strtod(text.c_str(), &end);
            if (end == text.c_str() || *end != '\0' || !(v > 0) || !std::isfinite(v))
                return "must be a positive number, got '" + text + "'";
            return {};
        },
        "POSITIVE");
}

}  // namespace

void ScanOptions::add_to(CLI::App& cmd) {
    cmd.add_option("--u", settings.u, "Cylinder vertices around a ring (U)")->capture_default_str();
    cmd.add_option("--v", settings.v, "Cross-sections along the V axis (V)")->capture_default_str();
    cmd.add_option("--max-groups", settings.max_groups, "Preallocated cylinders (max groups)")
        ->capture_default_str();
    cmd.add_option("--epsilon", settings.epsilon,
                   "Grouping distance in world units (default: 1.75 sphere diameters)")
        ->check(positive_number());
    cmd.add_option("--radial", radial,
                   "Radial function: maxima (circle maxima) or gaussian (blended gaussians)")
        ->capture_default_str();
    cmd.add_option("--smoothing", settings.section.smoothing_iterations,
                   "Smoothing iterations I (circle maxima)")
        ->capture_default_str();
    cmd.add_option("--tension", settings.section.tension, "Gaussian tension k (blended gaussians)")
        ->capture_default_str();
    cmd.add_option("--axis", axis,
                   "Cylinder axes: path (each cylinder follows its stream, arcs stay round) or vertical "
                   "(the paper's V axis)")
        ->capture_default_str();
}

ScanSettings ScanOptions::resolve() const {
    ScanSettings s = settings;
    if (radial == "maxima") {
        s.section.function = RadialFunction::kCircleMaxima;
    } else if (radial == "gaussian") {
        s.section.function = RadialFunction::kGaussianBlend;
    } else {
        throw std::invalid_argument(fmt::format("--radial must be 'maxima' or 'gaussian', got '{}'", radial));
    }
    if (axis == "path") {
        s.axis = CylinderAxis::kPath;
    } else if (axis == "vertical") {
        s.axis = CylinderAxis::kVertical;
    } else {
        throw std::invalid_argument(fmt::format("--axis must be 'path' or 'vertical', got '{}'", axis));
    }
    return s;
}

std::string default_method(const std::string& given, const SceneDesc& scene) {
    if (!given.empty()) return given;
    return scene.simulation == SimulationKind::kDiffuse ? "sprites" : "scan";
}

void add_method_option(CLI::App& cmd, std::string& method, bool rendered) {
    auto* opt = cmd.add_option(
        "--method", method,
        rendered ? "Surface method: scan (sphere scan conversion), slices (marching slices), "
                   "screen (screen-space fluid, drawn without a mesh), volume (density volume, "
                   "raycast), hybrid (streams as scan cylinders, the rest as slices) or sprites (the "
                   "particles of a diffuse object; default for diffuse scenes, scan otherwise)"
                 : "Surface method: scan (sphere scan conversion), slices (marching slices), volume "
                   "(density volume: marching cubes, or an OpenVDB grid with --out FILE.vdb) or hybrid "
                   "(streams as scan cylinders, the rest as slices)");
    if (!rendered) opt->capture_default_str();
    opt->check(CLI::Validator(
        [rendered](std::string& m) -> std::string {
            if (m == "scan" || m == "slices" || m == "volume" || m == "hybrid" ||
                (rendered && (m == "screen" || m == "sprites")))
                return {};
            if (m == "sprites")
                return "'sprites' draws a diffuse object and makes no mesh: use it with 'run'";
            if (m == "screen") return "'screen' draws the fluid and makes no mesh: use it with 'run'";
            return fmt::format("'{}' is not a surface method: choose 'scan', 'slices', 'volume', 'hybrid'{}",
                               m, rendered ? ", 'screen' or 'sprites'" : "");
        },
        "METHOD"));
}

void ScreenOptions::add_to(CLI::App& cmd) {
    // Each smoothing has its own default number of passes unless --filter-iterations names one, in
    // whichever order the two options come.
    cmd.add_option_function<std::string>(
           "--depth-filter",
           [this](const std::string& name) {
               parse_depth_smoothing(name, settings.smoothing);
               if (!iterations_given)
                   settings.filter_iterations = default_filter_iterations(settings.smoothing);
           },
           "Screen-space fluid: how the depth is smoothed: narrow-range (default), bilateral or "
           "curvature-flow")
        ->check(CLI::Validator(
            [](std::string& name) -> std::string {
                DepthSmoothing s;
                if (parse_depth_smoothing(name, s)) return {};
                return fmt::format(
                    "'{}' is not a depth filter: choose narrow-range, bilateral or curvature-flow", name);
            },
            "SMOOTHING"));
    cmd.add_option_function<int>(
        "--filter-iterations",
        [this](int n) {
            settings.filter_iterations = n;
            iterations_given = true;
        },
        "Screen-space fluid: smoothing passes over the depth, sharing --filter-radius (narrow-range: 2, "
        "bilateral: 1, curvature-flow: 40)");
    cmd.add_option("--filter-radius", settings.filter_radius,
                   "Screen-space fluid: smoothing width in particle radii (the pixels follow depth)")
        ->capture_default_str();
    cmd.add_option("--spray", settings.spray_neighbours,
                   "Screen-space fluid: particles with fewer than N neighbours are drawn as spray (0: none)")
        ->capture_default_str();
}

void SlicesOptions::add_to(CLI::App& cmd) {
    cmd.add_option("--voxel", voxel,
                   "Marching slices: cube edge in world units (default: radius / 2); density volume: the "
                   "grid's voxel (default: a quarter of the kernel radius, grown to fit --max-dim)")
        ->check(positive_number());
    cmd.add_option("--block", block, "Marching slices: cubes per block edge (n, a block is n^3 cubes)")
        ->capture_default_str()
        ->check(CLI::Range(2, 128));
    cmd.add_option("--field", field,
                   "Marching slices: 'spacing' puts the surface one radius outside the particles at any "
                   "particle spacing (R_c and iso follow the data's spacing); 'classic' is the fixed field "
                   "calibrated for particles two radii apart")
        ->capture_default_str()
        ->check(CLI::IsMember({"spacing", "classic"}));
    cmd.add_option("--spacing", spacing,
                   "Marching slices, spacing field: the particles' spacing in world units (default: "
                   "measured from their number density on the first frame of 1,024 particles or more)")
        ->check(positive_number());
    cmd.add_flag(
           "--anisotropic{3}", anisotropy,
           "Marching slices: anisotropic kernels (Yu & Turk 2013), stretched along the surface by up to "
           "the given ratio of longest to shortest axis (default 3, at most 4): "
           "flat water flat, thin sheets one sheet")
        ->check(CLI::Range(1.0, double(kMaxAnisotropy)));
    cmd.add_option("--anisotropic-smoothing", anisotropy_smoothing,
                   "Marching slices, anisotropic kernels: how far each centre moves to its neighbours' "
                   "weighted mean (0: not at all, 1: all the way)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1.0));
    cmd.add_flag("--exhaustive-seeds", exhaustive,
                 "Marching slices: also seed from every grid column, so empty cavities (bubbles holding no "
                 "particle) are found too; slower");
}

void SlicesOptions::apply(SlicesSettings& s) const {
    s.voxel = voxel;
    s.block_cubes = block;
    s.exhaustive_seeds = exhaustive;
    s.spacing = spacing;
    s.anisotropy = anisotropy;
    s.anisotropy_smoothing = anisotropy_smoothing;
    parse_slice_field(field, s.field);
}

void SceneOptions::add_to(CLI::App& cmd, const std::string& frames_help) {
    std::string builtin;
    for (std::string_view n : builtin_scene_names())
        builtin += (builtin.empty() ? "" : ", ") + std::string(n);
    cmd.add_option("--scene", name, "Built-in scene (" + builtin + ") or a scene file FILE.json")
        ->capture_default_str();
    cmd.add_option("--frames", frames, frames_help)
        ->capture_default_str()
        ->check(CLI::Range(1, kMaxRunFrames));
    cmd.add_option("--warmup", warmup, "Simulated frames before frame 0 (default: the scene's)")
        ->check(CLI::Range(0, kMaxWarmupFrames));
}

SceneDesc SceneOptions::resolve() const {
    SceneDesc scene = resolve_scene(name);
    if (warmup >= 0) scene.warmup_frames = warmup;
    validate_scene(scene);
    return scene;
}

void add_threads_option(CLI::App& cmd, int& threads, const std::string& help) {
    cmd.add_option("--threads", threads, help)->capture_default_str()->check(CLI::Range(0, 1024));
}

void write_json_file(const std::string& path, const nlohmann::json& doc) {
    io::write_text_file(path, doc.dump(2) + "\n");
}

void parse_size(const std::string& text, int& width, int& height) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
        throw std::invalid_argument(fmt::format("--size must look like 1280x720, got '{}'", text));
    if (w < 16 || h < 16 || w > 8192 || h > 8192)
        throw std::invalid_argument(
            fmt::format("--size must be between 16x16 and 8192x8192, got '{}'", text));
    width = w, height = h;
}

}  // namespace rivulet::cli

namespace rivulet::cli {

void VolumeOptions::add_to(CLI::App& cmd, bool offline) {
    cmd.add_option("--kernel", settings.kernel_radii,
                   "Density volume: the poly6 kernel's support radius in particle radii")
        ->capture_default_str();
    cmd.add_option("--max-dim", settings.max_dim, "Density volume: cells per axis at most (a multiple of 8)")
        ->capture_default_str();
    cmd.add_option("--iso", settings.iso,
                   "Density volume: the surface's level of F (default: calibrated so a flat surface lies "
                   "one radius outside the outermost particles)");
    if (offline)
        cmd.add_flag("--level-set", level_set,
                     "Density volume, --out FILE.vdb: also write a narrow-band signed distance grid "
                     "\"surface\" of the iso-surface");
}

VolumeSettings VolumeOptions::resolve(float voxel) const {
    VolumeSettings s = settings;
    s.voxel = voxel;
    return s;
}

}  // namespace rivulet::cli
