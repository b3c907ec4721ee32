// rivulet: particle fluids to surfaces and pictures. The command line is a contract (DESIGN §4).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string_view>

#include "cli/commands.h"
#include "cluster/launcher_env.h"
#include "runtime/lib/allocator_tuning.h"

namespace {

// A bad command line (unknown option, value out of range) exits 2; a failure while running exits 1.
constexpr int kUsageError = 2;

// Under a launcher of several processes only `mesh` divides its work; any other command would run as
// that many copies writing the same files.
bool refuses_launcher(int argc, char** argv) {
    if (rivulet::cluster::launcher_world_size() <= 1) return false;
#if RIVULET_WITH_MPI
    if (argc > 1 && std::string_view(argv[1]) == "mesh") return false;
    std::fprintf(stderr,
                 "rivulet: error: only `rivulet mesh` runs across MPI ranks; run this command without "
                 "mpirun (docs/cluster.md)\n");
#else
    (void)argc, (void)argv;
    std::fprintf(stderr,
                 "rivulet: error: started by an MPI launcher with several processes, but this "
                 "rivulet was built without MPI (install libopenmpi-dev and rebuild)\n");
#endif
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    if (refuses_launcher(argc, argv)) return 1;
    rivulet::keep_freed_memory_for_reuse();
    CLI::App app{"Rivulet: a task-graph runtime that turns particle fluids into surfaces and pictures"};
    app.require_subcommand(1);
    int status = 0;
    rivulet::cli::add_run_command(app, status);
    rivulet::cli::add_mesh_command(app, status);
    rivulet::cli::add_simulate_command(app, status);
    rivulet::cli::add_replay_command(app, status);
    rivulet::cli::add_trace_summary_command(app, status);
    rivulet::cli::add_bench_command(app, status);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // One line in the same form as every other error; the option parser's hint line is left out.
        std::fprintf(stderr, "rivulet: error: %s (see rivulet --help)\n", e.what());
        return kUsageError;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rivulet: error: %s\n", e.what());
        return 1;
    }
    return status;
}
