#include <memory>

#include "runtime/lib/mesh_extraction.h"

#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/hybrid_extractor.h"
#include "runtime/lib/scan_jobs.h"
#include "runtime/lib/slices_jobs.h"
#include "runtime/lib/stage_summary.h"
#include "runtime/lib/volume_jobs.h"
#include "systems/particles/particle_set.h"
#include "systems/particles/radius_estimate.h"
#include "systems/scan/scan_converter.h"
#include "systems/slices/slices_extractor.h"
#include "systems/volume/volume_mesh.h"

namespace rivulet {
namespace {

// Runs `graph` `repeat` times; medians of the wall time and of each job into `result`.
void time_graph(FrameGraph& graph, int repeat, MeshResult& result) {
    std::vector<double> totals;
    std::vector<std::vector<double>> stages(0);
    for (int r = 0; r < repeat; ++r) {
        graph.run();
        totals.push_back(graph.last_run_ms());
        stages.resize(graph.job_count());
        for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j) stages[j].push_back(graph.job_ms(j));
    }
    result.total_ms = median(totals);
    for (FrameGraph::JobId j = 0; j < graph.job_count(); ++j)
        result.stage_ms.emplace_back(graph.job_name(j), median(stages[j]));
}

void extract_slices(const ParticleSet& particles, const MeshSettings& req, MeshResult& result) {
    SlicesSettings s = req.slices;
    s.radius = result.radius;
    SlicesExtractor slices(s, particles.size());
    SurfaceMesh out;
    FrameGraph graph;
    add_slices_jobs(
        graph, slices, [&particles] { return particles.positions(); },
        [&out]() -> SurfaceMesh& { return out; });
    time_graph(graph, req.repeat, result);
    result.voxel = slices.voxel();
    result.rc = slices.rc();
    result.iso = slices.iso();
    result.slices_field = slice_field_name(s.field), result.spacing = slices.field().spacing;
    result.anisotropy = s.anisotropy, result.anisotropy_smoothing = s.anisotropy_smoothing;
    result.blocks = slices.stats().active_blocks;
    result.seeds = slices.stats().seeds, result.cubes = slices.stats().cubes;
    const TriangleMeshView view = out.view();
    result.mesh.vertices.assign(view.vertices.begin(), view.vertices.end());
    result.mesh.indices.assign(view.indices.begin(), view.indices.end());
    result.hash = mesh_hash(result.mesh);
}

// The density volume built by the frame's jobs, then (unless only the volume is wanted) meshed by
// marching cubes on its grid, timed as one more stage.
void extract_volume(const ParticleSet& particles, const MeshSettings& req, MeshResult& result) {
    VolumeSettings s = req.volume;
    s.radius = result.radius;
    VolumeBuilder builder(s, particles.size());
    auto volume = std::make_unique<DensityVolume>();
    builder.prepare(*volume);
    DensityVolume& v = *volume;
    FrameGraph graph;
    add_volume_jobs(
        graph, builder, [&particles] { return particles.positions(); },
        [&v]() -> DensityVolume& { return v; });
    time_graph(graph, req.repeat, result);
    result.voxel = v.grid.voxel, result.rc = v.grid.h, result.iso = v.iso, result.blocks = v.stored;
    if (req.mesh_volume) {
        std::vector<double> ms;
        for (int r = 0; r < req.repeat; ++r) {
            const auto t0 = std::chrono::steady_clock::now();
            result.mesh = mesh_density_volume(v.view());
            ms.push_back(
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        }
        result.stage_ms.emplace_back("volume.mesh", median(ms));
        result.total_ms += median(ms);
        result.hash = mesh_hash(result.mesh);
    } else {
        result.hash = v.hash();
    }
    result.volume = std::move(volume);
}

// Streams as cylinders, the rest as marching slices: one mesh of the cylinders and spheres, then the
// slices' welded mesh.
void extract_hybrid(const ParticleSet& particles, const MeshSettings& req, MeshResult& result,
                    const ScanSettings& scan) {
    SlicesSettings s = req.slices;
    s.radius = result.radius;
    HybridExtractor hybrid(scan, s, particles.size());
    ScanOutput cylinders;
    hybrid.prepare_output(cylinders);
    SurfaceMesh mesh;
    FrameGraph graph;
    hybrid.add_jobs(
        graph, [&particles] { return particles.positions(); },
        [&cylinders]() -> ScanOutput& { return cylinders; }, [&mesh]() -> SurfaceMesh& { return mesh; });
    time_graph(graph, req.repeat, result);
    result.groups = cylinders.draw_count;
    result.isolated = cylinders.sphere_count;
    result.blocks = hybrid.slices().stats().active_blocks;
    result.mesh = assemble_scan_mesh(cylinders, hybrid.scan().layout(), result.radius);
    const TriangleMeshView view = mesh.view();
    const auto base = static_cast<std::uint32_t>(result.mesh.vertex_count());
    result.mesh.vertices.insert(result.mesh.vertices.end(), view.vertices.begin(), view.vertices.end());
    for (const std::uint32_t i : view.indices) result.mesh.indices.push_back(base + i);
    result.hash = mesh_hash(result.mesh);
}

}  // namespace

MeshResult extract_mesh(const ParticleCloud& cloud, const MeshSettings& req) {
    const std::size_t n = cloud.x.size();
    if (n == 0) throw std::invalid_argument("no particles to mesh");
    ParticleSet particles(n);
    for (std::size_t i = 0; i < n; ++i)
        particles.push(cloud.x[i], cloud.y[i], cloud.z[i], 0, 0, 0, static_cast<std::uint32_t>(i));

    MeshResult result;
    result.particles = n;
    result.radius = req.radius > 0 ? req.radius : estimate_particle_radius(particles.positions());
    if (!(result.radius > 0))
        throw std::invalid_argument(
            "cannot estimate a particle radius (all particles coincide): pass --radius");
    if (req.method == "slices") {
        extract_slices(particles, req, result);
        return result;
    }
    if (req.method == "volume") {
        extract_volume(particles, req, result);
        return result;
    }
    if (req.method != "scan" && req.method != "hybrid")
        throw std::invalid_argument(fmt::format("unknown method '{}'", req.method));
    ScanSettings s = req.scan;
    s.radius = result.radius;
    s.fit_v_range(cloud.y);
    if (req.method == "hybrid") {
        extract_hybrid(particles, req, result, s);
        return result;
    }
    ScanOutput out;
    FrameGraph graph;
    auto positions = [&particles] { return particles.positions(); };
    auto output = [&out]() -> ScanOutput& { return out; };
    std::unique_ptr<ScanConverter> vertical;
    std::unique_ptr<OrientedScan> path;
    if (s.axis == CylinderAxis::kPath) {
        path = std::make_unique<OrientedScan>(s, n);
        path->prepare_output(out);
        add_oriented_scan_jobs(graph, *path, positions, output);
    } else {
        vertical = std::make_unique<ScanConverter>(s, n);
        vertical->prepare_output(out);
        add_scan_jobs(graph, *vertical, positions, output);
    }
    time_graph(graph, req.repeat, result);
    result.groups = out.draw_count;
    result.isolated = out.sphere_count;
    result.mesh = assemble_scan_mesh(out, vertical ? vertical->layout() : path->layout(), result.radius);
    result.hash = mesh_hash(result.mesh);
    return result;
}

}  // namespace rivulet
