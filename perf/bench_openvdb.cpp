// Peer comparison: OpenVDB (tools::ParticlesToLevelSet, then tools::volumeToMesh) beside Rivulet's
// marching slices, on the lattice blocks of bench_slices (spacing 2 r, r = 0.01), both with voxel = r / 2,
// at 1 and 2 threads (tbb::global_control bounds both). Median wall time of `--repeat` runs (default 5).
// OpenVDB rasterises each particle as a sphere of radius `--vdb-radius` r and meshes the zero level set
// without adaptivity; marching slices uses its defaults (R_c = 2 r, calibrated iso). The default 1.8 r:
// spheres of radius r at spacing 2 r only touch, so OpenVDB then meshes every sphere separately (2.8 M
// triangles for 24k particles); at 1.8 r the union is solid and the triangle counts match (flat faces
// 1.8 r outside the outer centres, against 1 r for marching slices). `--vdb-offset` r shrinks the level
// set afterwards (tools::LevelSetFilter::offset); with 0.8 r it took seconds and did not close the
// union in our runs, so it is off by default.
//   bench_openvdb [--repeat K] [--max-side 29|50] [--vdb-radius F] [--vdb-offset F]
#include <fmt/format.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <vector>

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

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The particle list interface ParticlesToLevelSet reads.
struct VdbParticles {
    using PosType = openvdb::Vec3R;
    const rivulet::ParticleSet* set;
    double radius;
    std::size_t size() const { return set->size(); }
    void getPos(std::size_t n, openvdb::Vec3R& p) const { p = {set->x()[n], set->y()[n], set->z()[n]}; }
    void getPosRad(std::size_t n, openvdb::Vec3R& p, openvdb::Real& r) const {
        getPos(n, p);
        r = radius;
    }
};

}  // namespace

int main(int argc, char** argv) {
    int repeat = 5, max_side = 50;
    double vdb_radius = 1.8, vdb_offset = 0.0;  // in particle radii
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--repeat")) repeat = std::max(1, std::atoi(argv[i + 1]));
        if (!std::strcmp(argv[i], "--max-side")) max_side = std::atoi(argv[i + 1]);
        if (!std::strcmp(argv[i], "--vdb-radius")) vdb_radius = std::atof(argv[i + 1]);
        if (!std::strcmp(argv[i], "--vdb-offset")) vdb_offset = std::atof(argv[i + 1]);
    }
    openvdb::initialize();
    const float radius = 0.01f, voxel = 0.5f * radius;
    fmt::print("lattice blocks (spacing 2 r, r = {}), voxel = r / 2, median of {}\n", radius, repeat);
    fmt::print("{:>9} {:>7} {:>16} {:>10} {:>10}  {}\n", "particles", "threads", "method", "total_ms",
               "triangles", "stages (ms)");
    fmt::print("openvdb: spheres of {} r, level set offset {} r\n", vdb_radius, vdb_offset);
    for (int side : {29, 50}) {
        if (side > max_side) continue;
        rivulet::ParticleSet set(std::size_t(side) * side * side);
        std::uint32_t id = 0;
        for (int k = 0; k < side; ++k)
            for (int j = 0; j < side; ++j)
                for (int i = 0; i < side; ++i)
                    set.push(2 * radius * float(i), 2 * radius * float(j), 2 * radius * float(k), 0, 0, 0,
                             id++);
        for (int threads : {1, 2}) {
            rivulet::ThreadControl control(threads);
            // OpenVDB.
            std::vector<double> totals, raster_ms, mesh_ms;
            std::size_t vdb_triangles = 0;
            for (int r = 0; r <= repeat; ++r) {  // run 0 warms up
                const auto t0 = std::chrono::steady_clock::now();
                auto grid = openvdb::createLevelSet<openvdb::FloatGrid>(voxel, 3.0);
                openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
                raster.setRmin(0.5);
                raster.rasterizeSpheres(VdbParticles{&set, vdb_radius * radius});
                raster.finalize(true);
                if (vdb_offset != 0.0) {
                    openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
                    filter.offset(static_cast<float>(vdb_offset * radius));
                }
                const double t_raster = ms_since(t0);
                std::vector<openvdb::Vec3s> points;
                std::vector<openvdb::Vec3I> tris;
                std::vector<openvdb::Vec4I> quads;
                const auto t1 = std::chrono::steady_clock::now();
                openvdb::tools::volumeToMesh(*grid, points, tris, quads, 0.0, 0.0);
                const double t_mesh = ms_since(t1);
                if (r == 0) continue;
                totals.push_back(ms_since(t0));
                raster_ms.push_back(t_raster);
                mesh_ms.push_back(t_mesh);
                vdb_triangles = tris.size() + 2 * quads.size();
            }
            fmt::print(
                "{:>9} {:>7} {:>16} {:>10.2f} {:>10}  ParticlesToLevelSet+offset {:.2f}, volumeToMesh "
                "{:.2f}\n",
                set.size(), threads, "openvdb", median(totals), vdb_triangles, median(raster_ms),
                median(mesh_ms));
            // Marching slices.
            rivulet::SlicesSettings s;
            s.radius = radius;
            s.voxel = voxel;
            rivulet::SlicesExtractor slices(s, set.size());
            rivulet::SurfaceMesh mesh;
            rivulet::FrameGraph graph;
            rivulet::add_slices_jobs(
                graph, slices, [&set] { return set.positions(); },
                [&mesh]() -> rivulet::SurfaceMesh& { return mesh; });
            graph.run();
            std::vector<double> slice_totals, blocks_ms, normals_ms;
            for (int r = 0; r < repeat; ++r) {
                graph.run();
                slice_totals.push_back(graph.last_run_ms());
                for (rivulet::FrameGraph::JobId j = 0; j < graph.job_count(); ++j) {
                    if (graph.job_name(j) == "slices.blocks") blocks_ms.push_back(graph.job_ms(j));
                    if (graph.job_name(j) == "slices.normals") normals_ms.push_back(graph.job_ms(j));
                }
            }
            fmt::print("{:>9} {:>7} {:>16} {:>10.2f} {:>10}  slices.blocks {:.2f}, slices.normals {:.2f}\n",
                       set.size(), threads, "marching slices", median(slice_totals), mesh.triangle_count(),
                       median(blocks_ms), median(normals_ms));
        }
    }
    return 0;
}
