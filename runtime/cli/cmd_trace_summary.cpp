// rivulet trace-summary: what a `--trace` capture says, without opening a trace viewer.
#include <fmt/format.h>

#include "cli/commands.h"
#include "runtime/lib/trace_summary.h"

namespace rivulet::cli {

void add_trace_summary_command(CLI::App& app, int& status) {
    auto path = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand(
        "trace-summary", "Per-job statistics, critical path, parallelism and overlap of a --trace capture");
    cmd->add_option("file", *path, "Trace JSON written by rivulet run --trace")->required();
    cmd->callback([path, &status] {
        fmt::print("{}", format_trace_summary(summarize_trace_file(*path)));
        status = 0;
    });
}

}  // namespace rivulet::cli
