// rivulet bench: throughput of every scene x method x thread count. Each case runs as its own
// `rivulet run` process, so thread pools, llvmpipe and the allocator start fresh exactly as a user's run
// would; the results become bench.json, bench.md and PNG plots (gnuplot).
#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <thread>

#include "cli/commands.h"
#include "runtime/lib/bench_report.h"
#include "runtime/lib/surface_system.h"
#include "systems/io/io_limits.h"
#include "systems/io/json_file.h"
#include "systems/io/output_file.h"
#include "systems/scenes/scene_json.h"

extern char** environ;

namespace rivulet::cli {
namespace {

struct BenchOptions {
    std::string scenes = "fountain,faucet,hose";
    std::string methods = "scan";
    std::string threads = "1,2,N";
    int frames = 60;
    int timing_warmup = 10;
    std::string size = "1280x720";
    bool no_render = false;
    std::string out = "bench";
};

std::vector<std::string> split_list(const std::string& text, const char* option) {
    std::vector<std::string> items;
    std::stringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        if (item.empty()) throw std::invalid_argument(fmt::format("{}: empty entry in '{}'", option, text));
        items.push_back(item);
    }
    if (items.empty()) throw std::invalid_argument(fmt::format("{} needs at least one entry", option));
    return items;
}

// "1,2,N": N is every hardware thread; duplicates (N = 2 on a 2-core machine) are dropped.
std::vector<int> thread_counts(const std::string& text) {
    const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
    std::vector<int> counts;
    for (const std::string& item : split_list(text, "--threads")) {
        int t = 0;
        if (item == "N") {
            t = hardware;
        } else {
            std::size_t used = 0;
            try {
                t = std::stoi(item, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used != item.size() || t < 1 || t > 1024)
                throw std::invalid_argument(
                    fmt::format("--threads: '{}' is not a count in [1, 1024] or N", item));
        }
        if (std::find(counts.begin(), counts.end(), t) == counts.end()) counts.push_back(t);
    }
    return counts;
}

// Runs `args` with stdout and stderr into `log`; returns the exit status.
int run_process(const std::vector<std::string>& args, const std::string& log) {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    std::vector<char*> argv;
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err != 0) throw std::runtime_error(fmt::format("cannot start '{}': {}", args[0], std::strerror(err)));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw std::runtime_error("waitpid failed");
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

nlohmann::json read_json(const std::string& path) {
    return io::read_json_file(path, io::kMaxReportFileBytes, "bench case reports");
}

int bench(const BenchOptions& o) {
    if (o.frames < 1 || o.frames > 100000)
        throw std::invalid_argument(fmt::format("--frames must be in [1, 100000], got {}", o.frames));
    int width = 0, height = 0;
    parse_size(o.size, width, height);
    const std::vector<std::string> scenes = split_list(o.scenes, "--scenes");
    const std::vector<std::string> methods = split_list(o.methods, "--methods");
    const std::vector<int> threads = thread_counts(o.threads);
    // Every scene is read and checked here, so a bad one fails before any case runs.
    // A diffuse scene has one method, sprites; fluid scenes run every method asked for but sprites.
    std::vector<bool> diffuse;
    for (const std::string& scene : scenes)
        diffuse.push_back(resolve_scene(scene).simulation == SimulationKind::kDiffuse);
    for (const std::string& method : methods) parse_surface_method(method);
    const auto methods_of = [&](std::size_t s) {
        std::vector<std::string> m;
        if (diffuse[s]) return std::vector<std::string>{"sprites"};
        for (const std::string& method : methods)
            if (method != "sprites") m.push_back(method);
        return m;
    };
    const std::string exe = std::filesystem::read_symlink("/proc/self/exe").string();
    const std::string cases_dir = o.out + "/cases";
    std::filesystem::create_directories(cases_dir);

    std::vector<BenchCase> cases;
    std::size_t total = 0;
    for (std::size_t s = 0; s < scenes.size(); ++s) total += methods_of(s).size() * threads.size();
    for (std::size_t s = 0; s < scenes.size(); ++s)
        for (const std::string& method : methods_of(s))
            for (int t : threads) {
                const std::string& scene = scenes[s];
                const std::string stem = fmt::format("{}/{}_{}_t{}", cases_dir,
                                                     std::filesystem::path(scene).stem().string(), method, t);
                std::vector<std::string> args = {exe,
                                                 "run",
                                                 "--scene",
                                                 scene,
                                                 "--method",
                                                 method,
                                                 "--threads",
                                                 std::to_string(t),
                                                 "--frames",
                                                 std::to_string(o.frames + o.timing_warmup),
                                                 "--timing-warmup",
                                                 std::to_string(o.timing_warmup),
                                                 "--out",
                                                 "",
                                                 "--size",
                                                 o.size,
                                                 "--json",
                                                 stem + ".json"};
                if (o.no_render) args.push_back("--no-render");
                fmt::print(stderr, "bench [{}/{}] {} {} at {} threads\n", cases.size() + 1, total, scene,
                           method, t);
                if (const int rc = run_process(args, stem + ".log"); rc != 0)
                    throw std::runtime_error(
                        fmt::format("case {} / {} / {} threads failed (exit {}); see {}.log", scene, method,
                                    t, rc, stem));
                cases.push_back({scene, method, t, read_json(stem + ".json")});
            }
    derive_scaling(cases);

    nlohmann::json meta;
    meta["description"] = fmt::format(
        "{} frames per case after {} warm-up frames, {}, {} hardware threads; medians per case; speedup and "
        "efficiency against the same scene and method at its fewest threads.",
        o.frames, o.timing_warmup,
        o.no_render ? "extraction only" : fmt::format("rendered at {}x{}", width, height),
        std::thread::hardware_concurrency());
    meta["frames"] = o.frames;
    meta["timing_warmup"] = o.timing_warmup;
    meta["size"] = o.size;
    meta["render"] = !o.no_render;
    meta["hardware_threads"] = std::thread::hardware_concurrency();
    write_json_file(o.out + "/bench.json", bench_json(cases, meta));
    const std::string md = bench_markdown(cases, meta);
    io::write_text_file(o.out + "/bench.md", md);
    fmt::print("{}", md);

    write_gnuplot_inputs(cases, o.out);
    const std::string gnuplot = "/usr/bin/gnuplot";
    if (!std::filesystem::exists(gnuplot)) {
        fmt::print(stderr,
                   "rivulet bench: warning: gnuplot not found (.ci/install-deps installs it); no plots\n");
        return 0;
    }
    const std::string cwd = std::filesystem::current_path().string();
    std::filesystem::current_path(o.out);
    const int rc = run_process({gnuplot, "plots.gp"}, "plots.log");
    std::filesystem::current_path(cwd);
    if (rc != 0) throw std::runtime_error(fmt::format("gnuplot failed; see {}/plots.log", o.out));
    fmt::print("\nresults: {0}/bench.json, {0}/bench.md, plots {0}/scaling.png and {0}/stages.png\n", o.out);
    return 0;
}

}  // namespace

void add_bench_command(CLI::App& app, int& status) {
    auto opts = std::make_shared<BenchOptions>();
    CLI::App* cmd = app.add_subcommand(
        "bench", "Throughput of scenes x methods x thread counts: bench.json, bench.md and PNG plots");
    cmd->add_option("--scenes", opts->scenes, "Comma-separated scenes (built-in names or FILE.json)")
        ->capture_default_str();
    cmd->add_option("--methods", opts->methods, "Comma-separated surface methods")->capture_default_str();
    cmd->add_option("--threads", opts->threads, "Comma-separated thread counts; N = all hardware threads")
        ->capture_default_str();
    cmd->add_option("--frames", opts->frames, "Timed frames per case")->capture_default_str();
    cmd->add_option("--timing-warmup", opts->timing_warmup, "Frames run first in each case and not timed")
        ->capture_default_str()
        ->check(CLI::Range(0, 100000));
    cmd->add_option("--size", opts->size, "Picture size WxH")->capture_default_str();
    cmd->add_flag("--no-render", opts->no_render, "Simulate and extract only (no GL)");
    cmd->add_option("--out", opts->out, "Directory for bench.json, bench.md, plots and per-case logs")
        ->capture_default_str();
    cmd->callback([opts, &status] { status = bench(*opts); });
}

}  // namespace rivulet::cli
