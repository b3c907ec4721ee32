#include <cmath>
#include <string>

#include "rivulet/surface.h"
#include "runtime/api/api_support.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/scan_jobs.h"
#include "runtime/lib/slices_jobs.h"
#include "runtime/lib/volume_jobs.h"
#include "systems/particles/aligned_array.h"
#include "systems/particles/radius_estimate.h"
#include "systems/scan/scan_mesh.h"
#include "systems/slices/slices_extractor.h"
#include "systems/volume/volume_builder.h"
#include "systems/volume/volume_mesh.h"

namespace rivulet {

// One method's system, its frame graph and its output, built for one set of settings and a particle
// capacity and kept while both still fit. Each mirrors `rivulet mesh` (runtime/lib/mesh_extraction.cpp),
// so both give the same bytes.
struct SurfaceExtractor::Workspace {
    AlignedArray<float> x, y, z;  // the call's particles, staged as structure of arrays
    std::size_t n = 0;
    api::WorkerArena arena;

    struct Built {
        SurfaceSettings settings;  // as given, radius resolved
        std::size_t capacity = 0;
        bool fits(const SurfaceSettings& s, std::size_t particles) const {
            return particles <= capacity && s.radius == settings.radius && s.voxel == settings.voxel &&
                   s.anisotropy == settings.anisotropy;
        }
    };
    struct Slices : Built {
        std::unique_ptr<SlicesExtractor> system;
        SurfaceMesh mesh;
        std::unique_ptr<FrameGraph> graph;
    } slices;
    struct Scan : Built {
        float v_top = 0, v_bottom = 0;
        std::unique_ptr<OrientedScan> system;  // cylinders along the streams (ScanSettings' default axis)
        ScanOutput out;
        std::unique_ptr<FrameGraph> graph;
        TriangleMesh mesh;
    } scan;
    struct Volume : Built {
        std::unique_ptr<VolumeBuilder> system;
        DensityVolume out;
        std::unique_ptr<FrameGraph> graph;
        TriangleMesh mesh;
    } volume;

    ConstPositions positions() const { return {x.span(n), y.span(n), z.span(n)}; }
    // Capacity for a rebuilt system: room to grow, so a slowly growing simulation rebuilds rarely.
    std::size_t capacity_for(std::size_t particles) const { return particles + particles / 4; }

    // Checks the staged particles and the settings, estimates the radius if asked, runs the method.
    MeshView run(const SurfaceSettings& settings);
    MeshView run_slices(const SurfaceSettings& s, tbb::task_arena& workers);
    MeshView run_scan(const SurfaceSettings& s, tbb::task_arena& workers);
    MeshView run_volume(const SurfaceSettings& s, tbb::task_arena& workers);
};

namespace {

MeshView view_of(const TriangleMesh& mesh, float radius) {
    return {mesh.vertices, mesh.indices, radius};
}

}  // namespace

MeshView SurfaceExtractor::Workspace::run_slices(const SurfaceSettings& s, tbb::task_arena& workers) {
    if (!slices.system || !slices.fits(s, n)) {
        SlicesSettings settings;
        settings.radius = s.radius;
        settings.voxel = s.voxel;
        settings.anisotropy = s.anisotropy;
        slices.graph.reset();
        slices.system = std::make_unique<SlicesExtractor>(settings, capacity_for(n));
        // A sweep scratch per thread now: grown on demand, a second one would first be made whenever
        // the calls happened to run two blocks at once, which a busy machine may put off for many calls.
        slices.system->reserve_scratch(static_cast<std::size_t>(workers.max_concurrency()));
        slices.graph = std::make_unique<FrameGraph>();
        add_slices_jobs(
            *slices.graph, *slices.system, [this] { return positions(); },
            [this]() -> SurfaceMesh& { return slices.mesh; });
        slices.settings = s, slices.capacity = capacity_for(n);
    }
    slices.system->forget_field();
    workers.execute([&] { slices.graph->run(); });
    const TriangleMeshView v = slices.mesh.view();
    return {v.vertices, v.indices, s.radius};
}

MeshView SurfaceExtractor::Workspace::run_scan(const SurfaceSettings& s, tbb::task_arena& workers) {
    // The settings' V range is validated with the rest, so a new range rebuilds the converter.
    ScanSettings settings;
    settings.radius = s.radius;
    settings.fit_v_range(y.span(n));
    const float v_top = settings.v_top, v_bottom = settings.v_bottom;
    if (!scan.system || !scan.fits(s, n) || v_top != scan.v_top || v_bottom != scan.v_bottom) {
        scan.graph.reset();
        scan.system = std::make_unique<OrientedScan>(settings, capacity_for(n));
        scan.system->prepare_output(scan.out);
        scan.graph = std::make_unique<FrameGraph>();
        add_oriented_scan_jobs(
            *scan.graph, *scan.system, [this] { return positions(); },
            [this]() -> ScanOutput& { return scan.out; });
        scan.settings = s, scan.capacity = capacity_for(n), scan.v_top = v_top, scan.v_bottom = v_bottom;
    }
    workers.execute([&] { scan.graph->run(); });
    assemble_scan_mesh(scan.out, scan.system->layout(), s.radius, scan.mesh);
    return view_of(scan.mesh, s.radius);
}

MeshView SurfaceExtractor::Workspace::run_volume(const SurfaceSettings& s, tbb::task_arena& workers) {
    if (!volume.system || !volume.fits(s, n)) {
        VolumeSettings settings;
        settings.radius = s.radius;
        settings.voxel = s.voxel;
        volume.graph.reset();
        volume.system = std::make_unique<VolumeBuilder>(settings, capacity_for(n));
        volume.system->prepare(volume.out);
        volume.graph = std::make_unique<FrameGraph>();
        add_volume_jobs(
            *volume.graph, *volume.system, [this] { return positions(); },
            [this]() -> DensityVolume& { return volume.out; });
        volume.settings = s, volume.capacity = capacity_for(n);
    }
    workers.execute([&] {
        volume.graph->run();
        volume.mesh = mesh_density_volume(volume.out.view());
    });
    return view_of(volume.mesh, s.radius);
}

SurfaceExtractor::SurfaceExtractor() : workspace_(std::make_unique<Workspace>()) {}
SurfaceExtractor::~SurfaceExtractor() = default;
SurfaceExtractor::SurfaceExtractor(SurfaceExtractor&&) noexcept = default;
SurfaceExtractor& SurfaceExtractor::operator=(SurfaceExtractor&&) noexcept = default;

MeshView SurfaceExtractor::extract(std::span<const float> xyz, const SurfaceSettings& settings) {
    if (xyz.size() % 3 != 0)
        throw Error("positions: " + std::to_string(xyz.size()) + " floats is not 3 a particle");
    Workspace& w = *workspace_;
    return api::translate_errors([&] {
        w.n = xyz.size() / 3;
        w.x.reserve(w.n), w.y.reserve(w.n), w.z.reserve(w.n);
        for (std::size_t i = 0; i < w.n; ++i)
            w.x[i] = xyz[3 * i], w.y[i] = xyz[3 * i + 1], w.z[i] = xyz[3 * i + 2];
        return w.run(settings);
    });
}

MeshView SurfaceExtractor::extract(std::span<const float> x, std::span<const float> y,
                                   std::span<const float> z, const SurfaceSettings& settings) {
    if (x.size() != y.size() || x.size() != z.size())
        throw Error("positions: x, y and z hold " + std::to_string(x.size()) + ", " +
                    std::to_string(y.size()) + " and " + std::to_string(z.size()) + " values");
    Workspace& w = *workspace_;
    return api::translate_errors([&] {
        w.n = x.size();
        w.x.reserve(w.n), w.y.reserve(w.n), w.z.reserve(w.n);
        std::copy(x.begin(), x.end(), w.x.data());
        std::copy(y.begin(), y.end(), w.y.data());
        std::copy(z.begin(), z.end(), w.z.data());
        return w.run(settings);
    });
}

MeshView SurfaceExtractor::Workspace::run(const SurfaceSettings& settings) {
    if (n == 0) throw Error("no particles to mesh");
    for (std::size_t i = 0; i < n; ++i)
        if (!std::isfinite(x[i]) || !std::isfinite(y[i]) || !std::isfinite(z[i]))
            throw Error("positions: particle " + std::to_string(i) +
                        " has a coordinate that is NaN or infinite");
    if (!(settings.radius >= 0) || !std::isfinite(settings.radius))
        throw Error("radius must be positive and finite (0: estimated), got " +
                    std::to_string(settings.radius));
    if (!(settings.voxel >= 0) || !std::isfinite(settings.voxel))
        throw Error("voxel must be positive and finite (0: automatic), got " +
                    std::to_string(settings.voxel));
    tbb::task_arena& workers = arena.get(settings.threads);
    SurfaceSettings s = settings;
    if (s.radius == 0) {
        workers.execute([&] { s.radius = estimate_particle_radius(positions()); });
        if (!(s.radius > 0))
            throw Error("cannot estimate a particle radius (all particles coincide): set the radius");
    }
    switch (s.method) {
        case Method::kSlices:
            return run_slices(s, workers);
        case Method::kScan:
            return run_scan(s, workers);
        case Method::kVolume:
            return run_volume(s, workers);
    }
    throw Error("unknown surface method " + std::to_string(int(s.method)));
}

std::uint64_t mesh_hash(const MeshView& mesh) {
    return mesh_hash(TriangleMeshView{mesh.vertices, mesh.indices});
}

}  // namespace rivulet
