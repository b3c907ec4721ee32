// The density volume (Inácio et al., "Interactive Simulation and Visualization of Fluids with Surface
// Raycasting"): milliseconds to build a frame's sparse volume from particles with the frame's jobs (bounds,
// bin sort, brick allocation, splat), per input x --max-dim x thread count; with --render, the render
// thread's upload and raycast of that volume too. Inputs are particle files (e.g. `rivulet simulate`
// output of any phase of a scene, or another code's) and a generated block of --block^3 particles on a
// lattice of spacing 2 --radius. Prints one row per case, medians over --repeat builds.
//
//   bench_volume [--input a.ply,b.ply] [--radius R] [--block 100] [--max-dim 128,256] [--fill]
//                [--threads 1,2] [--repeat 15] [--render] [--size 1280x720] [--scene dambreak]
//
// With --render, each row also uploads and raycasts its volume --repeat times in a Renderer of --size
// whose llvmpipe has as many threads as the row (a new GL context per row), the camera the --scene's
// (looking at the tank) for files and one framing the block for the block; upload and raycast are
// medians with GL finished after each (Renderer::set_time_passes).
#include <fmt/format.h>
#include <tbb/task_arena.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "perf/support/bench_util.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/thread_control.h"
#include "runtime/lib/volume_jobs.h"
#include "systems/io/particle_io.h"
#include "systems/particles/radius_estimate.h"
#include "systems/render/renderer.h"
#include "systems/scenes/scene_json.h"

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
    bool fill = false, per_job = false, render = false;
    std::string size = "1280x720", scene_name = "dambreak";
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
    app.add_flag("--render", render, "Also upload and raycast each row's volume (median ms)");
    app.add_option("--size", size, "Picture size WxH for --render")->capture_default_str();
    app.add_option("--scene", scene_name, "Scene whose camera and look --render uses for files")
        ->capture_default_str();
    CLI11_PARSE(app, argc, argv);

    std::vector<Case> cases;
    for (const std::string& f : bench::split_list(inputs)) cases.push_back(from_file(f, radius));
    if (block_n > 0) cases.push_back(block(block_n, radius > 0 ? radius : 0.005f));

    fmt::print("medians of {} builds, ms; MB = stored bricks' samples\n", repeat);
    int width = 1280, height = 720;
    if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2) return 2;
    const SceneDesc scene = resolve_scene(scene_name);
    fmt::print("{:<22} {:>9} {:>7} {:>5} {:>12} {:>7} {:>7} {:>3} {:>8} {:>8} {:>8}{}\n", "input",
               "particles", "max-dim", "h/vx", "grid", "bricks", "MB", "thr", "bin", "splat", "total",
               render ? "   upload  raycast" : "");
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
                std::string drawn;
                if (render) {
                    const ThreadControl rasterizers(threads);  // LP_NUM_THREADS before the context
                    Renderer r(RenderSettings{width, height});
                    SceneDesc look = scene;
                    if (c.name.rfind("block", 0) == 0) {
                        // Three quarters view of the block from twice its size away.
                        const ParticleBounds b = particle_bounds(c.view());
                        const Vec3f mid{(b.lo[0] + b.hi[0]) / 2, (b.lo[1] + b.hi[1]) / 2,
                                        (b.lo[2] + b.hi[2]) / 2};
                        const float e = b.hi[0] - b.lo[0];
                        look = SceneDesc{};
                        look.camera.target = mid;
                        look.camera.eye = {mid.x + 1.4f * e, mid.y + 1.0f * e, mid.z + 1.8f * e};
                    }
                    r.set_scene(look);
                    r.set_volume_raycast({});
                    r.set_time_passes(true);
                    FrameView frame;
                    frame.volume = vol.view();
                    std::vector<double> up, cast;
                    for (int k = 0; k < repeat + 1; ++k) {
                        r.render(frame);
                        if (k == 0) continue;  // shader compile, first allocation
                        up.push_back(r.timings().volume_upload), cast.push_back(r.timings().volume);
                    }
                    drawn = fmt::format(" {:>8.2f} {:>8.2f}", median(up), median(cast));
                }
                fmt::print(
                    "{:<22} {:>9} {:>7} {:>5.1f} {:>12} {:>7} {:>7.1f} {:>3} {:>8.2f} {:>8.2f} {:>8.2f}{}\n",
                    c.name, c.x.size(), d, g.h / g.voxel,
                    fmt::format("{}x{}x{}", g.bx * kBrickCells, g.by * kBrickCells, g.bz * kBrickCells),
                    vol.stored, double(vol.stored) * kBrickSamples * 4 / 1e6, threads, median(bin),
                    median(splat), median(total), drawn);
                if (per_job)
                    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j)
                        fmt::print("    {:<20} {:>8.3f}\n", graph.job_name(j), median(jobs[j]));
                std::fflush(stdout);
            }
        }
    }
}
