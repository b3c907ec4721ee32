// Marching slices throughput: a cubic lattice block of particles (spacing 2 radii, the default field:
// R_c = 2 radii, voxel = radius / 2, the default block size) meshed through the slices.* frame-graph jobs
// at 1 and 2 threads (or --threads). Prints the median wall time of `--repeat` runs (default 5), the mesh
// hash (the same at every thread count) and the slowest stages.
//   bench_slices [--repeat K] [--block N] [--voxel-fraction F] [--threads 1,2,16]
#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "jobs/mesh_hash.h"
#include "perf/support/bench_util.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/slices_jobs.h"
#include "runtime/lib/thread_control.h"
#include "systems/particles/particle_set.h"
#include "systems/slices/slices_extractor.h"

namespace {

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
    int repeat = 5;
    std::uint32_t block = rivulet::SlicesSettings{}.block_cubes;
    float voxel_fraction = 0.5f;
    std::vector<long> thread_counts{1, 2};
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--threads"))
            thread_counts = rivulet::bench::parse_list(argv[i + 1], "threads");
        if (!std::strcmp(argv[i], "--repeat")) repeat = std::max(1, std::atoi(argv[i + 1]));
        if (!std::strcmp(argv[i], "--block")) block = static_cast<std::uint32_t>(std::atoi(argv[i + 1]));
        if (!std::strcmp(argv[i], "--voxel-fraction"))
            voxel_fraction = static_cast<float>(std::atof(argv[i + 1]));
    }
    const float radius = 0.01f;
    fmt::print(
        "marching slices, lattice blocks (spacing 2 r, r = {}), voxel = {} r, block {}^3 cubes, median of "
        "{}\n",
        radius, voxel_fraction, block, repeat);
    fmt::print("{:>9} {:>7} {:>10} {:>10} {:>8} {:>9}  slowest stages\n", "particles", "threads", "total_ms",
               "triangles", "blocks", "hash");
    for (int side : {29, 50}) {  // 24,389 and 125,000 particles
        rivulet::ParticleSet set(std::size_t(side) * side * side);
        std::uint32_t id = 0;
        for (int k = 0; k < side; ++k)
            for (int j = 0; j < side; ++j)
                for (int i = 0; i < side; ++i)
                    set.push(2 * radius * float(i), 2 * radius * float(j), 2 * radius * float(k), 0, 0, 0,
                             id++);
        rivulet::SlicesSettings s;
        s.radius = radius;
        s.voxel = voxel_fraction * radius;
        s.block_cubes = block;
        for (const long t : thread_counts) {
            const int threads = static_cast<int>(t);
            rivulet::ThreadControl control(threads);
            rivulet::SlicesExtractor slices(s, set.size());
            rivulet::SurfaceMesh mesh;
            rivulet::FrameGraph graph;
            rivulet::add_slices_jobs(
                graph, slices, [&set] { return set.positions(); },
                [&mesh]() -> rivulet::SurfaceMesh& { return mesh; });
            graph.run();  // warm-up: buffers grow to size
            std::vector<double> totals;
            std::vector<std::vector<double>> stages(graph.job_count());
            for (int r = 0; r < repeat; ++r) {
                graph.run();
                totals.push_back(graph.last_run_ms());
                for (rivulet::FrameGraph::JobId j = 0; j < graph.job_count(); ++j)
                    stages[j].push_back(graph.job_ms(j));
            }
            std::vector<std::pair<double, std::string>> by_time;
            for (rivulet::FrameGraph::JobId j = 0; j < graph.job_count(); ++j)
                by_time.emplace_back(median(stages[j]), graph.job_name(j));
            std::sort(by_time.rbegin(), by_time.rend());
            rivulet::Hasher h;
            h.add(mesh.view().vertices);
            h.add(mesh.view().indices);
            fmt::print("{:>9} {:>7} {:>10.2f} {:>10} {:>8} {:>9.9}  {} {:.2f}, {} {:.2f}, {} {:.2f}\n",
                       set.size(), threads, median(totals), mesh.triangle_count(),
                       slices.stats().active_blocks, rivulet::hash_hex(h.digest()), by_time[0].second,
                       by_time[0].first, by_time[1].second, by_time[1].first, by_time[2].second,
                       by_time[2].first);
        }
    }
    return 0;
}
