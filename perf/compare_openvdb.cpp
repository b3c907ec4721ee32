// Marching slices against OpenVDB on the same particles (issue 3's figure): OpenVDB rasterises every
// particle as a sphere of the particle radius into a narrow-band level set (tools::ParticlesToLevelSet)
// and meshes its zero crossing (tools::volumeToMesh), at the same voxel size. Prints ms and triangles for
// both at each thread count, the speedup, and the distance between the two surfaces both ways (each mesh's
// vertices sampled in the other's signed distance field).
//
// Timing: --repeat alternations of one OpenVDB run and one of ours (the median of kOurRuns runs of the
// slices frame graph, as `rivulet mesh --repeat`), medians of each side over the alternations. Both sides
// so sample the same stretch of time: on a shared machine a burst of load from elsewhere lasting a few
// hundred milliseconds otherwise lands wholly on the short side's block of runs.
//
//   build/perf/compare_openvdb --sizes 25000,125000,1000000 --threads 1,2 [--splash frame.ply]
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "perf/support/bench_util.h"
#include "runtime/lib/allocator_tuning.h"
#include "runtime/lib/mesh_extraction.h"
#include "runtime/lib/stage_summary.h"
#include "runtime/lib/thread_control.h"
#include "systems/io/particle_io.h"

namespace {

using namespace rivulet;

// The particle list concept of tools::ParticlesToLevelSet, over our SoA arrays.
struct VdbParticles {
    using PosType = openvdb::Vec3R;
    const ParticleCloud* cloud;
    double radius;
    std::size_t size() const { return cloud->size(); }
    void getPos(std::size_t i, openvdb::Vec3R& p) const { p = {cloud->x[i], cloud->y[i], cloud->z[i]}; }
    void getPosRad(std::size_t i, openvdb::Vec3R& p, openvdb::Real& r) const {
        getPos(i, p);
        r = radius;
    }
};

struct VdbResult {
    double ms = 0;
    openvdb::FloatGrid::Ptr grid;
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    std::size_t triangle_count() const { return triangles.size() + 2 * quads.size(); }
};

constexpr float kHalfWidth = 3.0f;  // narrow band, in voxels (OpenVDB's default)

VdbResult openvdb_mesh(const ParticleCloud& cloud, float radius, float voxel) {
    VdbResult r;
    const auto t0 = std::chrono::steady_clock::now();
    r.grid = openvdb::createLevelSet<openvdb::FloatGrid>(voxel, kHalfWidth);
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*r.grid);
    raster.setRmin(1.0);  // radius / voxel is 2 here; keep every particle
    raster.rasterizeSpheres(VdbParticles{&cloud, radius});
    raster.finalize(true);
    openvdb::tools::volumeToMesh(*r.grid, r.points, r.triangles, r.quads, 0.0);
    r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return r;
}

struct Distance {
    double mean = 0, p95 = 0;
};

// |phi| of `grid` at each point (world units), clamped to the band: a point farther than the band reads
// the background value, so the figures are lower bounds when points lie outside it (reported as p95).
Distance sample_distance(const openvdb::FloatGrid& grid, const std::vector<openvdb::Vec3s>& points) {
    openvdb::tools::GridSampler<openvdb::FloatGrid, openvdb::tools::BoxSampler> sampler(grid);
    std::vector<double> d;
    d.reserve(points.size());
    for (const auto& p : points) d.push_back(std::abs(double(sampler.wsSample(openvdb::Vec3d(p)))));
    Distance out;
    if (d.empty()) return out;
    for (double v : d) out.mean += v;
    out.mean /= double(d.size());
    std::sort(d.begin(), d.end());
    out.p95 = d[std::min(d.size() - 1, d.size() * 95 / 100)];
    return out;
}

// A water column of `n` particles on a cubic lattice of spacing 2 radius, twice as tall as wide.
ParticleCloud dam_block(std::size_t n, float radius) {
    const auto side = static_cast<std::size_t>(std::max(1.0, std::round(std::cbrt(double(n) / 2.0))));
    ParticleCloud c;
    const float s = 2.0f * radius;
    for (std::size_t j = 0; j < 2 * side; ++j)
        for (std::size_t k = 0; k < side; ++k)
            for (std::size_t i = 0; i < side; ++i) {
                c.x.push_back(float(i) * s), c.y.push_back(float(j) * s), c.z.push_back(float(k) * s);
            }
    return c;
}

std::vector<int> parse_ints(const std::string& text) {
    std::vector<int> v;
    std::size_t at = 0;
    while (at < text.size()) {
        std::size_t used = 0;
        v.push_back(std::stoi(text.substr(at), &used));
        at += used + 1;
    }
    return v;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Marching slices against OpenVDB ParticlesToLevelSet + volumeToMesh"};
    std::string sizes = "25000,125000,1000000", threads = "1,2", fields = "spacing", splash, json_out;
    std::vector<std::string> more_frames;
    float radius = 0.01f;
    int repeat = 5;
    constexpr int kOurRuns = 5;
    std::uint32_t block = rivulet::SlicesSettings{}.block_cubes;
    app.add_option("--sizes", sizes, "Dam-break block particle counts")->capture_default_str();
    app.add_option("--threads", threads, "Thread counts")->capture_default_str();
    app.add_option("--radius", radius, "Particle radius (voxel = radius / 2)")->capture_default_str();
    app.add_option("--repeat", repeat,
                   fmt::format("Alternations per case (one OpenVDB run, {} of ours); medians", kOurRuns))
        ->capture_default_str();
    app.add_option("--splash", splash, "A splashing frame (PLY) to compare as well");
    app.add_option("--frames", more_frames, "More particle files to compare (any format `mesh` reads)");
    app.add_option(
           "--fields", fields,
           "Marching slices fields: spacing, classic, anisotropic (the spacing field with --anisotropic), "
           "comma-separated")
        ->capture_default_str();
    app.add_option("--block", block, "Marching slices: cubes per block edge")->capture_default_str();
    app.add_option("--json", json_out, "Write the table as JSON");
    CLI11_PARSE(app, argc, argv);
    // The same malloc settings as the rivulet command (they apply to both libraries in this process).
    keep_freed_memory_for_reuse();
    openvdb::initialize();

    std::vector<std::pair<std::string, ParticleCloud>> inputs;
    for (int n : parse_ints(sizes))
        inputs.emplace_back(fmt::format("dam block {}", n), dam_block(std::size_t(n), radius));
    if (!splash.empty()) inputs.emplace_back("splash " + splash, read_particles(splash));
    for (const std::string& f : more_frames) inputs.emplace_back(f, read_particles(f));
    struct FieldChoice {
        std::string name;
        rivulet::SliceField field{};
        float anisotropy = 0;
    };
    std::vector<FieldChoice> field_list;
    for (const std::string& name : rivulet::bench::split_list(fields)) {
        FieldChoice f{name};
        if (name == "anisotropic")
            f.anisotropy = rivulet::kDefaultAnisotropy;
        else if (!rivulet::parse_slice_field(name, f.field)) {
            fmt::print(stderr, "--fields: '{}' is not spacing, classic or anisotropic\n", name);
            return 2;
        }
        field_list.push_back(f);
    }
    if (field_list.empty()) {
        fmt::print(stderr, "--fields: name spacing, classic or anisotropic\n");
        return 2;
    }

    nlohmann::json rows = nlohmann::json::array();
    fmt::print(
        "| input | particles | field | T | slices ms | slices tris | OpenVDB ms | OpenVDB tris | speedup | "
        "mean dist ours->vdb | mean dist vdb->ours | p95 ours->vdb |\n");
    fmt::print("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    for (const auto& [name, cloud] : inputs)
        for (const FieldChoice& field : field_list) {
            for (int t : parse_ints(threads)) {
                ThreadControl control(t);
                MeshSettings req;
                req.method = "slices";
                req.radius = radius;
                req.repeat = kOurRuns;
                req.slices.block_cubes = block;
                req.slices.field = field.field;
                req.slices.anisotropy = field.anisotropy;
                MeshResult ours;
                std::vector<double> our_ms, vdb_ms;
                VdbResult vdb;
                for (int k = 0; k < repeat; ++k) {
                    ours = extract_mesh(cloud, req);
                    our_ms.push_back(ours.total_ms);
                    vdb = openvdb_mesh(cloud, radius, ours.voxel);
                    vdb_ms.push_back(vdb.ms);
                }
                ours.total_ms = median(our_ms);
                const double vdb_median = median(vdb_ms);
                // Our vertices in OpenVDB's distance field; OpenVDB's vertices in our mesh's distance field.
                std::vector<openvdb::Vec3s> our_points;
                for (std::size_t v = 0; v < ours.mesh.vertex_count(); ++v)
                    our_points.emplace_back(ours.mesh.vertices[6 * v], ours.mesh.vertices[6 * v + 1],
                                            ours.mesh.vertices[6 * v + 2]);
                std::vector<openvdb::Vec3I> our_tris;
                for (std::size_t i = 0; i + 2 < ours.mesh.indices.size(); i += 3)
                    our_tris.emplace_back(ours.mesh.indices[i], ours.mesh.indices[i + 1],
                                          ours.mesh.indices[i + 2]);
                const auto xform = openvdb::math::Transform::createLinearTransform(ours.voxel);
                const auto our_sdf = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*xform, our_points,
                                                                                        our_tris, kHalfWidth);
                const Distance to_vdb = sample_distance(*vdb.grid, our_points);
                const Distance to_ours = sample_distance(*our_sdf, vdb.points);
                const double speedup = vdb_median / ours.total_ms;
                fmt::print(
                    "| {} | {} | {} | {} | {:.2f} | {} | {:.1f} | {} | {:.1f}x | {:.4f} r | {:.4f} r | "
                    "{:.4f} r |\n",
                    name, cloud.size(), field.name, t, ours.total_ms, ours.mesh.triangle_count(), vdb_median,
                    vdb.triangle_count(), speedup, to_vdb.mean / radius, to_ours.mean / radius,
                    to_vdb.p95 / radius);
                std::fflush(stdout);
                rows.push_back({{"input", name},
                                {"particles", cloud.size()},
                                {"field", field.name},
                                {"spacing_radii", ours.spacing / radius},
                                {"threads", t},
                                {"slices_ms", ours.total_ms},
                                {"slices_triangles", ours.mesh.triangle_count()},
                                {"openvdb_ms", vdb_median},
                                {"openvdb_triangles", vdb.triangle_count()},
                                {"speedup", speedup},
                                {"mean_distance_to_openvdb_radii", to_vdb.mean / radius},
                                {"mean_distance_from_openvdb_radii", to_ours.mean / radius},
                                {"stages", ours.stage_ms}});
            }
        }
    if (!json_out.empty()) std::ofstream(json_out) << rows.dump(2) << '\n';
    return 0;
}
