// Table 1 of Hoetzlein & Höllerer 2009 on this machine: sphere scan conversion of a falling-water
// stream of P particles, timed per stage through the frame graph that `rivulet run` and `rivulet mesh`
// use (add_scan_jobs).
//
//   bench_scan_table [--sizes 1000,2000,...] [--threads 1,2] [--runs 100] [--warmup 20] [--streams N]
//                    [--json FILE]
//
// The input is a deterministic synthetic stream (falling_stream below), not a simulation, so every P is
// exactly P particles and every run sees the same positions:
//   - each stream leaves a nozzle 1.5 m up with velocity (0.4, -0.3) m/s and falls under gravity,
//     following its parabola down to the ground (a 1.5 m drop, drifting ~0.2 m sideways);
//   - along the stream the particles sit in slices 1 radius (0.02 m) apart in depth: 75 slices;
//   - a slice is a sunflower disk of m particles about 1 radius apart (m = 13: a disk 4 particles wide,
//     the paper's water stream), rotated per slice, each particle jittered by up to +-0.25 radius per axis
//     from a fixed-seed counter RNG;
//   - S = ceil(P / 1000) parallel streams 0.35 m apart on a square grid, capped at 64 streams (so the
//     cylinder pool of 150 is never the limit); beyond 64 000 particles the 64 streams get denser slices
//     (128 000: ~27 per slice). Particles are dealt to streams and slices round-robin, so P is exact.
//     --streams N puts the P particles in N streams instead (N = 1: one stream, denser as P grows).
// Columns sum the jobs by name: bin_sort = bin_sort.*, grouping = grouping.* + grouping (neighbour
// search, rules and group lists), isolated+stage; a per-job table follows.
// Radius 0.02 (the ScanSettings default), U = 20, V = 120 as in Table 1; v_top / v_bottom half a radius
// beyond the stream's extent, as `rivulet mesh` does.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "perf/support/bench_util.h"
#include "perf/support/falling_stream.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/scan_jobs.h"
#include "runtime/lib/stage_summary.h"
#include "runtime/lib/thread_control.h"
#include "systems/particles/particle_set.h"
#include "systems/scan/scan_converter.h"

namespace {

using rivulet::FrameGraph;
using rivulet::perf::falling_stream;

constexpr float kRadius = rivulet::perf::kStreamRadius;

struct Row {
    std::size_t particles = 0;
    int threads = 0;
    int runs = 0;
    double total_ms = 0, bin_sort_ms = 0, grouping_ms = 0, deform_ms = 0, normals_ms = 0, iso_stage_ms = 0;
    std::map<std::string, double> job_ms;  // per job median
    std::vector<std::string> job_order;    // graph order
    std::uint64_t faces = 0, triangles = 0;
    std::uint32_t groups = 0, isolated = 0, bin_entries = 0, pool_exhausted = 0;
};

Row measure(const rivulet::ParticleSet& set, int threads, int warmup, int runs, rivulet::CylinderAxis axis) {
    const rivulet::ThreadControl control(threads);
    const auto y = set.y();
    const auto [lo, hi] = std::minmax_element(y.begin(), y.end());
    rivulet::ScanSettings settings;  // U = 20, V = 120, defaults otherwise
    settings.radius = kRadius;
    settings.v_top = *hi + 0.5f * kRadius;
    settings.v_bottom = *lo - 0.5f * kRadius;
    settings.axis = axis;
    rivulet::ScanOutput out;
    FrameGraph graph;
    auto positions = [&set] { return set.positions(); };
    auto output = [&out]() -> rivulet::ScanOutput& { return out; };
    std::unique_ptr<rivulet::ScanConverter> vertical;
    std::unique_ptr<rivulet::OrientedScan> path;
    if (axis == rivulet::CylinderAxis::kPath) {
        path = std::make_unique<rivulet::OrientedScan>(settings, set.size());
        path->prepare_output(out);
        rivulet::add_oriented_scan_jobs(graph, *path, positions, output);
    } else {
        vertical = std::make_unique<rivulet::ScanConverter>(settings, set.size());
        vertical->prepare_output(out);
        rivulet::add_scan_jobs(graph, *vertical, positions, output);
    }
    // Table columns by job name: bin_sort.* | grouping* | deform | normals | isolated, stage.
    enum Column { kBins, kGrouping, kDeform, kNormals, kIsoStage, kColumns };
    std::vector<Column> column(graph.job_count());
    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
        const std::string& n = graph.job_name(j);
        if (n.starts_with("scan.bin_") || n == "scan.begin")
            column[j] = kBins;
        else if (n == "oriented.link" || n == "oriented.skeleton" || n == "oriented.cylinders")
            column[j] = kGrouping;
        else if (n == "oriented.rings")
            column[j] = kDeform;
        else if (n == "oriented.normals")
            column[j] = kNormals;
        else if (n == "oriented.isolated" || n == "oriented.stage")
            column[j] = kIsoStage;
        else if (n == "scan.neighbours" || n == "scan.group" || n == "scan.spread" ||
                 n == "scan.list_offsets" || n == "scan.lists")
            column[j] = kGrouping;
        else if (n == "scan.deform")
            column[j] = kDeform;
        else if (n == "scan.normals")
            column[j] = kNormals;
        else if (n == "scan.isolated" || n == "scan.stage")
            column[j] = kIsoStage;
        else
            throw std::logic_error("bench_scan_table: no column for scan job '" + n + "'");
    }

    for (int r = 0; r < warmup; ++r) graph.run();
    std::vector<double> total;
    std::vector<std::vector<double>> columns(kColumns), jobs(graph.job_count());
    for (int r = 0; r < runs; ++r) {
        graph.run();
        total.push_back(graph.last_run_ms());
        double sum[kColumns] = {};
        for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
            sum[column[j]] += graph.job_ms(j);
            jobs[j].push_back(graph.job_ms(j));
        }
        for (int c = 0; c < kColumns; ++c) columns[c].push_back(sum[c]);
    }
    Row row;
    row.particles = set.size();
    row.threads = control.threads();
    row.runs = runs;
    row.total_ms = rivulet::median(total);
    row.bin_sort_ms = rivulet::median(columns[kBins]);
    row.grouping_ms = rivulet::median(columns[kGrouping]);
    row.deform_ms = rivulet::median(columns[kDeform]);
    row.normals_ms = rivulet::median(columns[kNormals]);
    row.iso_stage_ms = rivulet::median(columns[kIsoStage]);
    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
        row.job_ms[graph.job_name(j)] = rivulet::median(jobs[j]);
        row.job_order.push_back(graph.job_name(j));
    }
    row.triangles = out.triangles;
    row.faces = out.triangles + 80ull * out.sphere_count;  // an isolated particle is an 80-face icosphere
    row.groups = out.draw_count;
    row.isolated = out.sphere_count;
    row.bin_entries = out.bin_entries;
    row.pool_exhausted = out.pool_exhausted;
    return row;
}

int run(int argc, char** argv) {
    std::vector<long> sizes = {1000, 2000, 3000, 4000, 5000, 6000, 7000, 8000, 32000, 128000};
    std::vector<long> threads = {1, 2};
    int runs = 100, warmup = 20;
    long streams = 0;
    std::string json_path;
    rivulet::CylinderAxis axis = rivulet::CylinderAxis::kVertical;
    for (int i = 1; i < argc; ++i) {
        const std::string_view a = argv[i];
        auto value = [&]() -> std::string_view {
            if (i + 1 >= argc) throw std::invalid_argument(fmt::format("{} needs a value", a));
            return argv[++i];
        };
        if (a == "--sizes")
            sizes = rivulet::bench::parse_list(value(), "size");
        else if (a == "--threads")
            threads = rivulet::bench::parse_list(value(), "thread count");
        else if (a == "--runs")
            runs = static_cast<int>(rivulet::bench::parse_list(value(), "run count").front());
        else if (a == "--warmup")
            warmup = static_cast<int>(std::strtol(std::string(value()).c_str(), nullptr, 10));
        else if (a == "--json")
            json_path = value();
        else if (a == "--axis") {
            const std::string_view v = value();
            if (v != "path" && v != "vertical")
                throw std::invalid_argument(fmt::format("--axis must be path or vertical, got '{}'", v));
            axis = v == "path" ? rivulet::CylinderAxis::kPath : rivulet::CylinderAxis::kVertical;
        } else if (a == "--streams")
            streams = rivulet::bench::parse_list(value(), "stream count").front();
        else if (a == "--help" || a == "-h") {
            fmt::print(
                "usage: {} [--sizes 1000,2000,...] [--threads 1,2] [--runs 100] [--warmup 20] [--streams N] "
                "[--axis vertical|path] [--json FILE]\n",
                argv[0]);
            return 0;
        } else
            throw std::invalid_argument(fmt::format("unknown argument '{}' (try --help)", a));
    }

    std::vector<Row> rows;
    for (const long p : sizes) {
        const rivulet::ParticleSet set =
            falling_stream(static_cast<std::size_t>(p), static_cast<std::size_t>(streams));
        for (const long t : threads) {
            rows.push_back(measure(set, static_cast<int>(t), warmup, runs, axis));
            const Row& r = rows.back();
            std::fprintf(stderr, "P=%zu T=%d: %.3f ms\n", r.particles, r.threads, r.total_ms);
        }
    }

    fmt::print(
        "Sphere scan conversion, U=20 V=120, radius {}, {} timed runs after {} warm-up (medians, ms)\n\n",
        kRadius, runs, warmup);
    fmt::print(
        "| P | T | total ms | bin_sort | grouping | deform | normals | isolated+stage | faces | groups | "
        "isolated |\n");
    fmt::print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const Row& r : rows)
        fmt::print("| {} | {} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {} | {} | {} |\n",
                   r.particles, r.threads, r.total_ms, r.bin_sort_ms, r.grouping_ms, r.deform_ms,
                   r.normals_ms, r.iso_stage_ms, r.faces, r.groups, r.isolated);

    // Every job of the graph (the grouping column is several jobs).
    if (!rows.empty()) {
        fmt::print("\nPer-job medians (ms)\n\n| P | T |");
        for (const auto& n : rows.front().job_order) fmt::print(" {} |", n);
        fmt::print("\n|---:|---:|");
        for (std::size_t k = 0; k < rows.front().job_order.size(); ++k) fmt::print("---:|");
        fmt::print("\n");
        for (const Row& r : rows) {
            fmt::print("| {} | {} |", r.particles, r.threads);
            for (const auto& n : r.job_order) fmt::print(" {:.3f} |", r.job_ms.at(n));
            fmt::print("\n");
        }
    }

    // Speedup of the highest thread count over 1 thread, per P.
    const long tmax = *std::max_element(threads.begin(), threads.end());
    if (tmax > 1 && std::find(threads.begin(), threads.end(), 1L) != threads.end()) {
        fmt::print("\n| P | T=1 ms | T={} ms | speedup {}/1 |\n|---:|---:|---:|---:|\n", tmax, tmax, tmax);
        for (const long p : sizes) {
            const Row *one = nullptr, *many = nullptr;
            for (const Row& r : rows) {
                if (r.particles != static_cast<std::size_t>(p)) continue;
                if (r.threads == 1) one = &r;
                if (r.threads == tmax) many = &r;
            }
            if (one && many)
                fmt::print("| {} | {:.3f} | {:.3f} | {:.2f}x |\n", p, one->total_ms, many->total_ms,
                           one->total_ms / many->total_ms);
        }
    }

    if (!json_path.empty()) {
        nlohmann::json j;
        j["radius"] = kRadius;
        j["u"] = 20;
        j["v"] = 120;
        j["runs"] = runs;
        j["warmup"] = warmup;
        j["streams"] = streams > 0 ? fmt::format("{}", streams) : std::string("ceil(P/1000), at most 64");
        j["hardware_threads"] = rivulet::hardware_threads();
        for (const Row& r : rows) {
            j["rows"].push_back({{"particles", r.particles},
                                 {"threads", r.threads},
                                 {"total_ms", r.total_ms},
                                 {"bin_sort_ms", r.bin_sort_ms},
                                 {"grouping_ms", r.grouping_ms},
                                 {"deform_ms", r.deform_ms},
                                 {"normals_ms", r.normals_ms},
                                 {"isolated_stage_ms", r.iso_stage_ms},
                                 {"jobs_ms", r.job_ms},
                                 {"faces", r.faces},
                                 {"triangles", r.triangles},
                                 {"groups", r.groups},
                                 {"isolated", r.isolated},
                                 {"bin_entries", r.bin_entries},
                                 {"pool_exhausted", r.pool_exhausted}});
        }
        std::ofstream f(json_path);
        f << j.dump(2) << "\n";
        if (!f) throw std::runtime_error(fmt::format("cannot write {}", json_path));
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_scan_table: %s\n", e.what());
        return 1;
    }
}
