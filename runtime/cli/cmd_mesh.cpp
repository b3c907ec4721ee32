// rivulet mesh: particles from files to triangle meshes, timed without file I/O.
#include <fmt/format.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "cli/progress_bar.h"
#include "jobs/mesh_hash.h"
#include "jobs/mesh_quality.h"
#include "jobs/mesh_smoothing.h"
#include "jobs/smoothing_weights.h"
#include "runtime/lib/mesh_decomposition.h"
#include "runtime/lib/mesh_extraction.h"
#include "runtime/lib/thread_control.h"
#include "systems/io/mesh_io.h"
#include "systems/io/particle_io.h"
#include "systems/io/sequence_pattern.h"
#include "systems/io/vdb_writer.h"
#if RIVULET_WITH_MPI
#include "cluster/frame_batch.h"
#include "cluster/piece_gather.h"
#endif

namespace rivulet::cli {
namespace {

struct MeshOptions {
    std::string input;
    std::string method = "scan";
    float radius = 0;
    int threads = 0;
    int repeat = 1;
    int smooth = 0;
    std::string smooth_weights = "particles";
    bool decompose = false;
    std::string out;
    std::string json;
    ScanOptions scan;
    SlicesOptions slices;
    VolumeOptions volume;
};

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

struct FrameJob {
    std::string in, out;
};

nlohmann::json mesh_json(const MeshResult& r, const std::string& method) {
    nlohmann::json stages = nlohmann::json::object();
    for (const auto& [name, ms] : r.stage_ms) stages[name] = ms;
    nlohmann::json j = {{"particles", r.particles},
                        {"vertices", r.mesh.vertex_count()},
                        {"triangles", r.mesh.triangle_count()},
                        {"total_ms", r.total_ms},
                        {"stages", stages},
                        {"mesh_hash", hash_hex(r.hash)},
                        {"radius", r.radius}};
    const MeshQuality q = mesh_quality(r.mesh.vertices, 6, r.mesh.indices);
    j["quality"] = {{"degenerate_triangles", q.degenerate},  {"min_angle_deg", q.min_angle_deg},
                    {"min_angle_p05_deg", q.min_angle_p05},  {"mean_min_angle_deg", q.mean_min_angle_deg},
                    {"median_radius_ratio", q.median_ratio}, {"radius_ratio_p95", q.ratio_p95},
                    {"max_radius_ratio", q.max_ratio}};
    if (method == "slices") {
        j["voxel"] = r.voxel, j["rc"] = r.rc, j["iso"] = r.iso, j["blocks"] = r.blocks;
        j["field"] = r.slices_field, j["spacing"] = r.spacing;
        j["anisotropy"] = r.anisotropy, j["anisotropy_smoothing"] = r.anisotropy_smoothing;
        j["seeds"] = r.seeds, j["cubes"] = r.cubes;
    } else if (method == "volume") {
        const DensityGrid& g = r.volume->grid;
        j["voxel"] = r.voxel, j["kernel_radius"] = r.rc, j["iso"] = r.iso, j["bricks"] = r.blocks;
        j["grid"] = {g.samples_x(), g.samples_y(), g.samples_z()};
    } else {
        j["groups"] = r.groups, j["isolated"] = r.isolated;
        if (method == "hybrid") j["blocks"] = r.blocks;
    }
    return j;
}

// Reads, meshes and writes one frame; its JSON record. A single file (not a sequence) also gets its
// summary line on stdout.
nlohmann::json mesh_frame(const FrameJob& job, const MeshSettings& req, const MeshOptions& o, bool sequence) {
    const ParticleCloud cloud = read_particles(job.in);
    MeshResult r = extract_mesh(cloud, req);
    nlohmann::json smoothing;
    if (o.smooth > 0 && req.mesh_volume) {
        const auto start = std::chrono::steady_clock::now();
        // Weights from the particles (Löschner et al. 2023); spacing as the field had it, or the
        // classic two radii where the method has none.
        std::vector<float> weights;
        if (o.smooth_weights == "particles")
            smoothing_weights({cloud.x, cloud.y, cloud.z}, r.spacing > 0 ? r.spacing : 2.0f * r.radius,
                              r.mesh.vertices, weights);
        const SmoothingReport s = smooth_mesh(r.mesh.vertices, r.mesh.indices, o.smooth, weights);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
        r.hash = mesh_hash(r.mesh);
        smoothing = {{"iterations", o.smooth},          {"ms", ms},
                     {"weights", o.smooth_weights},     {"components", s.components},
                     {"unsmoothed_components", s.kept}, {"volume_before", s.volume_before},
                     {"volume_after", s.volume_after}};
    }
    if (!job.out.empty()) {
        if (req.mesh_volume)
            write_mesh(job.out, r.mesh.vertices, r.mesh.indices);
        else
            write_vdb(job.out, r.volume->view(), {.level_set = o.volume.level_set});
    }
    if (r.volume && r.rc < 1.5f * r.voxel && !sequence)
        fmt::print(stderr,
                   "rivulet: note: the kernel radius spans only {:.1f} voxels of the {} cells --max-dim "
                   "allows: thin parts may vanish; raise --max-dim or give --voxel\n",
                   r.rc / r.voxel, req.volume.max_dim);
    nlohmann::json j = mesh_json(r, o.method);
    j["input"] = job.in;
    if (!smoothing.is_null()) j["smoothing"] = smoothing;
    if (!sequence && r.volume) {
        const DensityGrid& g = r.volume->grid;
        fmt::print(
            "{}: {} particles -> {} bricks of a {}x{}x{} grid (voxel {:g}), {} vertices, {} triangles "
            "in {:.3f} ms (median of {}), {} {}\n",
            job.in, r.particles, r.blocks, g.samples_x(), g.samples_y(), g.samples_z(), r.voxel,
            r.mesh.vertex_count(), r.mesh.triangle_count(), r.total_ms, o.repeat,
            req.mesh_volume ? "mesh_hash" : "volume_hash", hash_hex(r.hash));
    } else if (!sequence) {
        fmt::print(
            "{}: {} particles -> {} vertices, {} triangles in {:.3f} ms (median of {}), mesh_hash {}\n",
            job.in, r.particles, r.mesh.vertex_count(), r.mesh.triangle_count(), r.total_ms, o.repeat,
            hash_hex(r.hash));
    }
    return j;
}

#if RIVULET_WITH_MPI
// The frames spread over the ranks of an MPI job (docs/cluster.md). Each rank writes the frames it
// meshes; rank 0 prints the progress, the summary and the --json of all of them. A frame that fails is
// reported (its file and rank) and the others go on; the exit status says whether any failed.
int mesh_over_ranks(const cluster::MpiSession& session, const std::vector<FrameJob>& jobs,
                    const MeshSettings& req, const MeshOptions& o, int threads) {
    ProgressBar bar("meshing", static_cast<int>(jobs.size()));
    const auto mesh_one = [&](int i) {
        const FrameJob& job = jobs[static_cast<std::size_t>(i)];
        cluster::FrameOutcome out;
        try {
            out.record = mesh_frame(job, req, o, true).dump();
        } catch (const std::exception& e) {
            out.ok = false, out.error = e.what();
            fmt::print(stderr, "rivulet: error: {} (rank {}): {}\n", job.in, session.rank(), e.what());
        }
        return out;
    };
    const cluster::BatchResult batch = cluster::run_frames_over_ranks(
        session, static_cast<int>(jobs.size()), mesh_one, [&](int done) { bar.update(done); });
    if (session.rank() != 0) return batch.failed > 0 ? 1 : 0;

    const int meshed = static_cast<int>(jobs.size()) - batch.failed;
    const double rate = batch.wall_seconds > 0 ? meshed / batch.wall_seconds : 0;
    fmt::print("meshed {} of {} frames over {} ranks x {} threads in {:.2f} s: {:.2f} frames/s{}\n", meshed,
               jobs.size(), session.size(), threads, batch.wall_seconds, rate,
               batch.failed > 0 ? fmt::format("; {} failed", batch.failed) : "");
    nlohmann::json per_rank = nlohmann::json::array();
    for (std::size_t r = 0; r < batch.ranks.size(); ++r) {
        const cluster::RankLoad& load = batch.ranks[r];
        fmt::print("  rank {}: {} frame{}, {:.2f} s meshing\n", r, load.frames, load.frames == 1 ? "" : "s",
                   load.busy_seconds);
        per_rank.push_back({{"frames", load.frames}, {"busy_s", load.busy_seconds}});
    }
    nlohmann::json frames = nlohmann::json::array();
    for (const cluster::FrameOutcome& f : batch.frames) {
        const std::string& input = jobs[static_cast<std::size_t>(f.index)].in;
        if (!f.ok) fmt::print("  failed: {} (rank {}): {}\n", input, f.rank, f.error);
        nlohmann::json j =
            f.ok ? nlohmann::json::parse(f.record) : nlohmann::json{{"input", input}, {"error", f.error}};
        j["rank"] = f.rank, j["seconds"] = f.seconds;
        frames.push_back(std::move(j));
    }
    if (!o.json.empty()) {
        nlohmann::json doc = {{"frames", std::move(frames)},
                              {"threads", threads},
                              {"method", o.method},
                              {"ranks", session.size()},
                              {"per_rank", std::move(per_rank)},
                              {"wall_s", batch.wall_seconds},
                              {"frames_per_s", rate},
                              {"failed", batch.failed}};
        write_json_file(o.json, doc);
    }
    return batch.failed > 0 ? 1 : 0;
}

// One frame split over the ranks by slabs of marching slices' blocks (runtime/lib/mesh_decomposition.h):
// each rank reads the file, keeps its slab and ghost margin and meshes it; rank 0 welds the pieces into
// one mesh (the whole frame's triangles), writes it and reports each piece.
int mesh_in_pieces(const cluster::MpiSession& session, const FrameJob& job, const MeshSettings& req,
                   const MeshOptions& o, int threads) {
    using Clock = std::chrono::steady_clock;
    const auto ms_since = [](Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    };
    // Every rank reads and meshes before the gather; one that fails alone would leave the others
    // waiting there, so they agree first whether all succeeded (the failed ranks then say why).
    ParticleCloud cloud;
    MeshPiece mine;
    std::string error;
    const auto start = Clock::now();
    try {
        cloud = read_particles(job.in);
        mine = extract_mesh_piece(cloud, req, session.rank(), session.size());
    } catch (const std::exception& e) {
        error = e.what();
    }
    const double piece_ms = ms_since(start);  // the piece with the frame's setup (grid, field, slab)
    const int ok = error.empty() ? 1 : 0;
    int all_ok = 0;
    MPI_Allreduce(&ok, &all_ok, 1, MPI_INT, MPI_MIN, session.comm());
    if (!ok) throw std::runtime_error(error);
    if (!all_ok) return 1;
    const auto gather_start = Clock::now();
    const std::vector<MeshPiece> pieces = cluster::gather_pieces(session, mine);
    if (session.rank() != 0) return 0;
    const double gather_ms = ms_since(gather_start);
    const auto weld_start = Clock::now();
    TriangleMesh mesh = weld_mesh_pieces(pieces);
    const double weld_ms = ms_since(weld_start), ms = ms_since(start);
    const std::uint64_t hash = mesh_hash(mesh);
    if (!job.out.empty()) write_mesh(job.out, mesh.vertices, mesh.indices);
    const char* axis_name[3] = {"x", "y", "z"};
    fmt::print(
        "{}: {} particles in {} pieces along {} -> {} vertices, {} triangles in {:.3f} ms, mesh_hash {}\n",
        job.in, cloud.x.size(), pieces.size(), axis_name[pieces[0].axis], mesh.vertex_count(),
        mesh.triangle_count(), ms, hash_hex(hash));
    fmt::print("  rank 0: {:.3f} ms to its piece, then {:.3f} ms gathering, {:.3f} ms welding\n", piece_ms,
               gather_ms, weld_ms);
    nlohmann::json parts = nlohmann::json::array();
    for (std::size_t r = 0; r < pieces.size(); ++r) {
        const MeshPiece& p = pieces[r];
        fmt::print("  rank {}: blocks [{}, {}), {} particles with ghosts, {} triangles, {:.3f} ms\n", r,
                   p.first_block, p.end_block, p.particles, p.indices.size() / 3, p.extract_ms);
        parts.push_back({{"rank", r},
                         {"first_block", p.first_block},
                         {"end_block", p.end_block},
                         {"particles", p.particles},
                         {"triangles", p.indices.size() / 3},
                         {"extract_ms", p.extract_ms}});
    }
    if (!o.json.empty()) {
        nlohmann::json doc = {{"input", job.in},
                              {"particles", cloud.x.size()},
                              {"vertices", mesh.vertex_count()},
                              {"triangles", mesh.triangle_count()},
                              {"total_ms", ms},
                              {"stages", {{"piece", piece_ms}, {"gather", gather_ms}, {"weld", weld_ms}}},
                              {"mesh_hash", hash_hex(hash)},
                              {"method", o.method},
                              {"threads", threads},
                              {"ranks", session.size()},
                              {"axis", axis_name[pieces[0].axis]},
                              {"pieces", std::move(parts)}};
        write_json_file(o.json, doc);
    }
    return 0;
}
#endif

int run(const MeshOptions& o) {
    if (o.repeat < 1 || o.repeat > 100000)
        throw std::invalid_argument(fmt::format("--repeat must be in [1, 100000], got {}", o.repeat));
    if (o.radius < 0 || !std::isfinite(o.radius))
        throw std::invalid_argument(fmt::format("--radius must be positive, got {}", o.radius));
    MeshSettings req;
    req.method = o.method;
    req.scan = o.scan.resolve();
    o.slices.apply(req.slices);
    if (o.method == "slices" && o.radius > 0) {
        SlicesSettings probe = req.slices;
        probe.radius = o.radius;
        if (const std::string err = probe.validate(); !err.empty()) throw std::invalid_argument(err);
    }
    {
        // Check the options before reading any file; radius and V extent come with the particles.
        ScanSettings probe = req.scan;
        probe.radius = 1, probe.v_top = 1, probe.v_bottom = 0;
        if (const std::string err = probe.validate(); !err.empty()) throw std::invalid_argument(err);
    }
    req.volume = o.volume.resolve(o.slices.voxel);
    req.mesh_volume = !ends_with(o.out, ".vdb");
    if (!req.mesh_volume && o.method != "volume")
        throw std::invalid_argument("--out FILE.vdb writes a density volume: use it with --method volume");
    if (o.volume.level_set && req.mesh_volume)
        throw std::invalid_argument("--level-set goes with --method volume --out FILE.vdb");
    if (o.method == "volume") {
        VolumeSettings probe = req.volume;
        probe.radius = o.radius > 0 ? o.radius : 1.0f;
        if (probe.voxel > 0 && o.radius <= 0) probe.voxel = 0;  // checked against h with the radius
        if (const std::string err = probe.validate(); !err.empty()) throw std::invalid_argument(err);
    }
    ThreadControl threads(o.threads);
    req.radius = o.radius;
    req.repeat = o.repeat;

    std::vector<FrameJob> jobs;
    const bool sequence = is_sequence_pattern(o.input);
    if (sequence) {
        if (!o.out.empty() && !is_sequence_pattern(o.out))
            throw std::invalid_argument("--out must contain {} when INPUT is a sequence pattern");
        for (const SequenceFrame& f : expand_sequence(o.input))
            jobs.push_back({f.path, o.out.empty() ? "" : sequence_output_path(o.out, f.number, f.width)});
    } else {
        jobs.push_back({o.input, o.out});
    }

    if (o.decompose) {
        if (sequence)
            throw std::invalid_argument(
                "--decompose splits one frame over the ranks: give one file (without it the ranks share "
                "a sequence's frames)");
        if (o.method != "slices")
            throw std::invalid_argument(
                "--decompose splits a frame by marching slices' blocks: use --method slices");
        if (o.slices.anisotropy > 0)
            throw std::invalid_argument("--decompose takes spherical kernels only (no --anisotropic)");
        if (o.smooth > 0 || o.repeat > 1)
            throw std::invalid_argument(
                "--smooth and --repeat work on one process's mesh: not with --decompose");
    }
#if RIVULET_WITH_MPI
    const cluster::MpiSession session;
    if (session.size() > 1) {
        if (o.decompose) return mesh_in_pieces(session, jobs[0], req, o, threads.threads());
        if (!sequence)
            throw std::invalid_argument(
                "under mpirun, rivulet mesh spreads the frames of a sequence over the ranks: give INPUT as a "
                "{} pattern, or split the one frame with --decompose");
        return mesh_over_ranks(session, jobs, req, o, threads.threads());
    }
#endif
    nlohmann::json per_frame = nlohmann::json::array();
    ProgressBar bar("meshing", static_cast<int>(jobs.size()));
    for (std::size_t i = 0; i < jobs.size(); ++i) {
        per_frame.push_back(mesh_frame(jobs[i], req, o, sequence));
        if (sequence) bar.update(static_cast<int>(i + 1));
    }
    if (!o.json.empty()) {
        nlohmann::json doc = sequence ? nlohmann::json{{"frames", per_frame}} : per_frame[0];
        doc["threads"] = threads.threads();
        doc["method"] = o.method;
        write_json_file(o.json, doc);
    }
    return 0;
}

}  // namespace

void add_mesh_command(CLI::App& app, int& status) {
    auto opts = std::make_shared<MeshOptions>();
    CLI::App* cmd = app.add_subcommand(
        "mesh", "Extract a triangle mesh from particle files (.ply, .xyz, .vtk, or a {} pattern)");
    cmd->add_option("input", opts->input, "Particle file, or a sequence pattern such as frames/frame_{}.ply")
        ->required();
    add_method_option(*cmd, opts->method, false);
    cmd->add_option("--radius", opts->radius,
                    "Particle radius in world units (default: half the median neighbour distance)");
    add_threads_option(*cmd, opts->threads, "Threads (0 = all)");
    cmd->add_option("--repeat", opts->repeat, "Extractions to time; total_ms is their median")
        ->capture_default_str();
    cmd->add_option("--out", opts->out,
                    "Mesh file to write: .obj, .ply or .vtk; with --method volume also .vdb, the density "
                    "as an OpenVDB grid (a {} pattern for sequences)");
    cmd->add_option("--json", opts->json, "Write counts, timings, triangle quality and mesh_hash as JSON");
    cmd->add_option("--smooth", opts->smooth,
                    "Taubin smoothing iterations after meshing, each component's volume kept (0: none)")
        ->capture_default_str()
        ->check(CLI::Range(0, 10000));
    cmd->add_option(
           "--smooth-weights", opts->smooth_weights,
           "How much each vertex is smoothed: 'particles' (Löschner et al. 2023: by how many particles "
           "hold it, so droplets and thin sheets keep their shape) or 'none' (all alike)")
        ->capture_default_str()
        ->check(CLI::IsMember({"particles", "none"}));
    cmd->add_flag("--decompose", opts->decompose,
                  "Under mpirun: split one frame over the ranks by slabs of blocks (--method slices), "
                  "welded into one mesh on rank 0 (docs/cluster.md); one process meshes it whole");
    opts->scan.add_to(*cmd);
    opts->slices.add_to(*cmd);
    opts->volume.add_to(*cmd, true);
    cmd->callback([opts, &status] { status = run(*opts); });
}

}  // namespace rivulet::cli
