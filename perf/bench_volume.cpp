// The density volume (Inácio et al., "Interactive Simulation and Visualization of Fluids with Surface
// Raycasting"): milliseconds to build a frame's sparse volume from particles with the frame's jobs (bounds,
// bin sort, brick allocation, splat), per input x --max-dim x thread count; with --render, the render
// thread's upload and raycast of that volume too. Inputs are particle files (e.g. `rivulet simulate`
// output of any phase of a scene, or another code's) and a generated block of --block^3 particles on a
// lattice of spacing 2 --radius. Prints one row per case, medians over --repeat builds.
//
//   bench_volume [--input a.ply,b.ply] [--radius R] [--block 100] [--max-dim 128,256] [--fill]
//                [--threads 1,2] [--repeat 15] [--render] [--size 1280x720]
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "perf/support/bench_util.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/volume_jobs.h"
#include "systems/io/particle_io.h"
#include "systems/particles/radius_estimate.h"

namespace {

using namespace rivulet;
using bench::median;

struct Case {
    std::string name;
    std::vector<float> x, y, z;
    float radius = 0;
    ConstPositions view() const { return {x, y, z}; }
};

Case block(int n, float radius) {
    Case c;
    c.name = fmt::format("block {}^3", n);
    c.radius = radius;
    const float spacing = 2.0f * radius;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i) {
                c.x.push_back(spacing * float(i));
                c.y.push_back(spacing * float(j));
                c.z.push_back(spacing * float(k));
            }
    return c;
}

Case from_file(const std::string& path, float radius) {
    const ParticleCloud cloud = read_particles(path);
    Case c;
    c.name = path.substr(path.find_last_of('/') + 1);
    c.x = cloud.x, c.y = cloud.y, c.z = cloud.z;
    c.radius = radius > 0 ? radius : estimate_particle_radius(c.view());
    return c;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{
        "Density volume: build ms (bounds, bin sort, allocation, splat) per input, --max-dim, threads"};
    std::string inputs, dims = "128,256", thread_list = "1,2";
    float radius = 0;
    int block_n = 0, repeat = 15;
    bool fill = false, per_job = false;
    app.add_option("--input", inputs, "Comma-separated particle files");
    app.add_option("--radius", radius, "Particle radius (default: estimated per file; the block's: 0.005)");
    app.add_option("--block", block_n, "Also a lattice block of N^3 particles (0: none)")
        ->capture_default_str();
    app.add_option("--max-dim", dims, "Comma-separated --max-dim values")->capture_default_str();
    app.add_flag("--fill", fill,
                 "Choose the voxel so the grid spans --max-dim cells (else the default voxel)");
    app.add_option("--threads", thread_list, "Comma-separated thread counts")->capture_default_str();
    app.add_option("--repeat", repeat, "Builds per row")->capture_default_str();
    app.add_flag("--jobs", per_job, "Also each job's median ms under its row");
    CLI11_PARSE(app, argc, argv);

    std::vector<Case> cases;
    for (const std::string& f : bench::split_list(inputs)) cases.push_back(from_file(f, radius));
    if (block_n > 0) cases.push_back(block(block_n, radius > 0 ? radius : 0.005f));

    fmt::print("medians of {} builds, ms; MB = stored bricks' samples\n", repeat);
    fmt::print("{:<22} {:>9} {:>7} {:>5} {:>12} {:>7} {:>7} {:>3} {:>8} {:>8} {:>8}\n", "input", "particles",
               "max-dim", "h/vx", "grid", "bricks", "MB", "thr", "bin", "splat", "total");
    for (const Case& c : cases) {
        for (const std::string& d : bench::split_list(dims)) {
            VolumeSettings s;
            s.radius = c.radius;
            s.max_dim = static_cast<std::uint32_t>(std::stoul(d));
            if (fill) {
                const ParticleBounds b = particle_bounds(c.view());
                float longest = 0;
                for (int a = 0; a < 3; ++a) longest = std::max(longest, b.hi[a] - b.lo[a] + 2 * s.h());
                s.voxel = longest / float(s.max_dim - 3);
            }
            for (const std::string& t : bench::split_list(thread_list)) {
                const int threads = std::stoi(t);
                VolumeBuilder builder(s, c.x.size());
                DensityVolume vol;
                builder.prepare(vol);
                FrameGraph graph;
                add_volume_jobs(
                    graph, builder, [&c] { return c.view(); }, [&vol]() -> DensityVolume& { return vol; });
                tbb::task_arena arena(threads);
                std::vector<double> total, bin, splat;
                std::vector<std::vector<double>> jobs(graph.job_count());
                for (int r = 0; r < repeat + 1; ++r) {
                    arena.execute([&] { graph.run(); });
                    if (r == 0) continue;  // first touch of the atlas
                    total.push_back(graph.last_run_ms());
                    double b = 0, sp = 0;
                    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
                        (graph.job_name(j) == "volume.splat" ? sp : b) += graph.job_ms(j);
                        jobs[j].push_back(graph.job_ms(j));
                    }
                    bin.push_back(b), splat.push_back(sp);
                }
                const DensityGrid& g = vol.grid;
                fmt::print(
                    "{:<22} {:>9} {:>7} {:>5.1f} {:>12} {:>7} {:>7.1f} {:>3} {:>8.2f} {:>8.2f} {:>8.2f}\n",
                    c.name, c.x.size(), d, g.h / g.voxel,
                    fmt::format("{}x{}x{}", g.bx * kBrickCells, g.by * kBrickCells, g.bz * kBrickCells),
                    vol.stored, double(vol.stored) * kBrickSamples * 4 / 1e6, threads, median(bin),
                    median(splat), median(total));
                if (per_job)
                    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j)
                        fmt::print("    {:<20} {:>8.3f}\n", graph.job_name(j), median(jobs[j]));
                std::fflush(stdout);
            }
        }
    }
}
