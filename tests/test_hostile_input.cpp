// Hostile input (issue 21): endless streams, huge files, absurd scene values, foreign traces and bad
// options each end in one clear error, before any large allocation or long loop.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "runtime/lib/recording.h"
#include "runtime/lib/trace_recorder.h"
#include "runtime/lib/trace_summary.h"
#include "support/test_support.h"
#include "systems/io/file_format_error.h"
#include "systems/io/io_limits.h"
#include "systems/io/mesh_io.h"
#include "systems/io/particle_io.h"
#include "systems/scenes/scene_json.h"
#include "systems/scenes/scene_limits.h"
#include "systems/sim/sph_desc.h"
#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"

using namespace rivulet;
using rivulet::test::run_cli;
using rivulet::test::temp_path;
using rivulet::test::write_text;

namespace {

template <class F>
std::string error_of(F&& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "no error";
}

std::string link_to_dev_zero(const std::string& name) {
    const std::string path = temp_path(name);
    std::filesystem::remove(path);
    std::filesystem::create_symlink("/dev/zero", path);
    return path;
}

// A file of `bytes` that takes no disk: `head` first, then a hole of zeros.
std::string sparse_file(const std::string& name, const std::string& head, std::uint64_t bytes) {
    const std::string path = temp_path(name);
    write_text(path, head);
    EXPECT_EQ(::truncate(path.c_str(), static_cast<off_t>(bytes)), 0);
    return path;
}

std::string contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos ? "" : "'" + part + "' not in: " + text;
}

// The one-line error every failure prints, and nothing else from the run.
void expect_one_error_line(const rivulet::test::Result& r, const std::string& part, int status = 1) {
    EXPECT_EQ(r.status, status) << r.output;
    EXPECT_EQ(r.output.rfind("rivulet: error: ", 0), 0u) << r.output;
    EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << r.output;
    EXPECT_EQ(contains(r.output, part), "");
}

}  // namespace

TEST(HostileInput, EndlessStreamsAreRefusedAsNotRegularFiles) {
    const std::string scene = link_to_dev_zero("zero-scene.json");
    expect_one_error_line(run_cli("run --no-render --frames 1 --scene " + scene), "not a regular file");
    expect_one_error_line(
        run_cli("bench --no-render --frames 1 --out " + temp_path("zero-bench") + " --scenes " + scene),
        "not a regular file");
    expect_one_error_line(run_cli("replay " + link_to_dev_zero("zero.rivrec")), "not a regular file");
    expect_one_error_line(run_cli("trace-summary " + link_to_dev_zero("zero-trace.json")),
                          "not a regular file");
    EXPECT_EQ(contains(error_of([&] { read_particles(link_to_dev_zero("zero.xyz")); }), "not a regular file"),
              "");
}

TEST(HostileInput, JsonDocumentsOverTheirCapAreRefusedBeforeReading) {
    const std::string scene = sparse_file("huge-scene.json", "{", io::kMaxSceneFileBytes + 1);
    expect_one_error_line(run_cli("run --no-render --frames 1 --scene " + scene), "limit for scene files");
    EXPECT_EQ(contains(error_of([&] { load_scene_file(scene); }), "16 MiB limit"), "");
    const std::string rec = sparse_file("huge.rivrec", "{", io::kMaxRecordingBytes + 1);
    EXPECT_EQ(contains(error_of([&] { read_recording(rec); }), "512 MiB limit for recordings"), "");
    const std::string trace = sparse_file("huge-trace.json", "{", io::kMaxTraceFileBytes + 1);
    EXPECT_EQ(contains(error_of([&] { summarize_trace_file(trace); }), "1 GiB limit for traces"), "");
}

TEST(HostileInput, DeeplyNestedJsonIsRefused) {
    const std::string path = temp_path("nested.json");
    write_text(path, std::string(100000, '[') + std::string(100000, ']'));
    EXPECT_EQ(contains(error_of([&] { load_scene_file(path); }), "nested deeper than 64"), "");
    // Brackets inside strings do not count.
    write_text(path, std::string("{\"name\": \"").append(80, '[').append("\"}"));
    EXPECT_EQ(load_scene_file(path).name, std::string(80, '['));
}

TEST(HostileInput, TextFormatsOverTheirCapAreRefusedBeforeParsing) {
    const std::uint64_t over = io::kMaxTextFileBytes + 1;
    EXPECT_EQ(contains(error_of([&] { read_particles(sparse_file("huge.xyz", "0 0 0\n", over)); }),
                       "XYZ file of 2147483649 bytes is over the 2 GiB limit for text formats"),
              "");
    const std::string ply_head =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
        "end_header\n";
    EXPECT_EQ(contains(error_of([&] { read_particles(sparse_file("huge.ply", ply_head, over)); }),
                       "ASCII PLY file of"),
              "");
    EXPECT_EQ(contains(error_of([&] { read_mesh(sparse_file("huge-mesh.ply", ply_head, over)); }),
                       "ASCII PLY file of"),
              "");
    EXPECT_EQ(
        contains(error_of([&] { read_mesh(sparse_file("huge.obj", "v 0 0 0\n", over)); }), "OBJ file of"),
        "");
    EXPECT_EQ(
        contains(error_of([&] {
                     read_particles(sparse_file(
                         "huge.vtk",
                         "# vtk DataFile Version 3.0\nx\nASCII\nDATASET POLYDATA\nPOINTS 1 float\n", over));
                 }),
                 "ASCII VTK file of"),
        "");
}

TEST(HostileInput, AnSphLatticeIsCountedNotWalked) {
    // 1e-6 m in a 0.25 m column: ~4e16 points. Refused by the grid before the lattice is even counted.
    const std::string scene = temp_path("fine-sph.json");
    write_text(scene, R"({"base": "dambreak", "sph": {"spacing": 1e-6}})");
    expect_one_error_line(run_cli("run --no-render --frames 1 --scene " + scene),
                          "sph.spacing is too small for sph.container.box");
    // A tank that fits the grid but a fluid far over max_particles: counted exactly, never walked.
    SphDesc d = make_dambreak();
    d.spacing = 0.002f;  // 0.25 x 0.5 x 0.3 m of fluid: 125 x 250 x 150 = 4,687,500 points
    d.support_ratio = 8.0f;
    EXPECT_EQ(sph_seed_count(d), 4'687'500u);
    EXPECT_EQ(contains(sph_desc_problem(d, 25000), "needs 4687500 particles but max_particles is 25000"), "");
    // A sphere too large to count saturates at once.
    d.fluid_boxes.clear();
    d.fluid_spheres.push_back({{0.5f, 0.5f, 0.15f}, 1e6f, {}});
    EXPECT_EQ(sph_seed_count(d), std::size_t{kMaxSceneParticles} + 1);
    EXPECT_EQ(contains(sph_desc_problem(d, kMaxSceneParticles), "needs more than 50000000 particles"), "");
}

TEST(HostileInput, SphereSeedCountMatchesTheLatticeItPlaces) {
    // The counted sphere and the one seed() fills agree point for point, also for radii on a lattice
    // distance (where float rounding decides).
    for (const float radius : {0.05f, 0.06f, 0.1f, 0.0999999f, 0.1000001f, 0.137f}) {
        SphDesc d = make_drop();
        d.spacing = 0.01f;
        d.fluid_boxes.clear();
        d.fluid_spheres = {{{0.3f, 0.4f, 0.3f}, radius, {}}};
        const std::size_t n = sph_seed_count(d);
        SphSimulation sim(d, n);
        ParticleSet ps;
        sim.seed(ps);
        EXPECT_EQ(ps.size(), n) << radius;
    }
}

TEST(HostileInput, WarmupFramesObeyOneLimitFromEverySource) {
    const std::string scene = temp_path("long-warmup.json");
    write_text(scene, R"({"base": "fountain", "warmup_frames": 2000000000})");
    expect_one_error_line(run_cli("run --no-render --frames 1 --scene " + scene),
                          "warmup_frames must be in [0, 1000000], got 2000000000");
    expect_one_error_line(run_cli("run --no-render --frames 1 --warmup 2000000"), "--warmup", 2);
    // A recording asking for 2e8 warm-up frames is refused before any input array is allocated.
    Recording r;
    r.scene = make_builtin_scene("fountain");
    r.scene.warmup_frames = 200'000'000;
    r.frames = {{1, 2}};
    r.inputs.resize(1);
    const std::string rec = temp_path("long-warmup.rivrec");
    write_recording(rec, r);
    EXPECT_EQ(contains(error_of([&] { read_recording(rec); }), "warmup_frames must be in [0, 1000000]"), "");
    expect_one_error_line(run_cli("replay " + rec), "warmup_frames");
}

TEST(HostileInput, PoolSamplesHaveADocumentedCeiling) {
    const std::string scene = temp_path("big-pool.json");
    write_text(scene, R"({"base": "fountain", "pool": {"nx": 4096, "nz": 4096}})");
    expect_one_error_line(
        run_cli("run --no-render --frames 1 --scene " + scene),
        std::string("pool.nx must be in [2, ").append(std::to_string(kMaxPoolSamples)).append("], got 4096"));
}

TEST(HostileInput, OptionErrorsAreOneLineWithTheUsageStatus) {
    expect_one_error_line(run_cli("run --frames -1"), "--frames: Value -1 not in range 1 to 1000000", 2);
    expect_one_error_line(run_cli("run --threads 100000"), "--threads", 2);
    expect_one_error_line(run_cli("mesh x.ply --voxel 0"), "--voxel: must be a positive number, got '0'", 2);
    expect_one_error_line(run_cli("run --no-such-option"), "--no-such-option", 2);
    expect_one_error_line(run_cli(""), "subcommand", 2);
    const auto help = run_cli("run --help");
    EXPECT_EQ(help.status, 0);
    EXPECT_EQ(contains(help.output, "--frames"), "");
}

TEST(HostileInput, PreallocationsThatGrowWithOptionsAreEstimatedAndRefused) {
    // The cylinder pool of --max-groups 100000 would reserve 5.9 GiB: refused before any of it.
    expect_one_error_line(run_cli("run --no-render --frames 1 --max-groups 100000"),
                          "scan conversion buffers for --max-groups 100000, --u 20, --v 120");
    expect_one_error_line(run_cli("run --no-render --frames 1 --max-groups 100000 --v 8192 --u 32"),
                          "limit 4 GiB");
    // A 2000-frame trace at 1024 threads asks for nothing up front (TraceCaptureGrowsWithWhatIsRecorded).
}

TEST(HostileInput, TraceCaptureGrowsWithWhatIsRecorded) {
    // 1024 threads and a cap of a million zones: nothing but the chunk tables until zones arrive.
    TraceRecorder big(1024);
    EXPECT_EQ(big.allocated_zones(), 0u);
    const std::uint16_t name = big.intern("job");
    big.record(name, 0, -1, 0, 1);
    EXPECT_EQ(big.allocated_zones(), big.chunk_zones());
    EXPECT_EQ(big.chunk_zones(), kMaxTraceZones / 4096);  // a quarter of each thread's share

    // The cap counts zones of all threads; beyond it zones are dropped and counted, not stored.
    TraceRecorder capped(2, kTraceChunkZones + 10);
    const std::uint16_t job = capped.intern("job");
    for (int i = 0; i < int(kTraceChunkZones) + 100; ++i) capped.record(job, 0, i, i, i + 1);
    EXPECT_EQ(capped.zones().size(), kTraceChunkZones + 10);
    EXPECT_EQ(capped.dropped(), 90u);
    EXPECT_EQ(capped.allocated_zones(), kTraceChunkZones + 10);

    // A small cap still leaves every thread room: chunks shrink to a quarter of a thread's share.
    TraceRecorder small(2, 4096);
    EXPECT_EQ(small.chunk_zones(), 512u);
}

namespace {

nlohmann::json capture(const nlohmann::json& jobs, const nlohmann::json& events) {
    return {{"traceEvents", events}, {"otherData", {{"format", "rivulet-trace-1"}, {"jobs", jobs}}}};
}

nlohmann::json zone(const std::string& name, const nlohmann::json& frame, const nlohmann::json& tid) {
    return {{"name", name}, {"ph", "X"}, {"tid", tid}, {"ts", 0}, {"dur", 1}, {"args", {{"frame", frame}}}};
}

std::string trace_error(const nlohmann::json& trace) {
    return error_of([&] { summarize_trace(trace); });
}

}  // namespace

TEST(HostileInput, TraceSummaryValidatesTheGraphAndEveryNumber) {
    const nlohmann::json ok_jobs = {{{"name", "A"}, {"after", nlohmann::json::array()}},
                                    {{"name", "B"}, {"after", {"A"}}}};
    const nlohmann::json one = nlohmann::json::array({zone("A", 0, 0)});
    EXPECT_EQ(trace_error(capture(ok_jobs, one)), "no error");

    const nlohmann::json self = {{{"name", "A"}, {"after", {"A"}}}};
    EXPECT_EQ(contains(trace_error(capture(self, one)), "cycle through 'A'"), "");
    const nlohmann::json loop = {{{"name", "A"}, {"after", {"C"}}},
                                 {{"name", "B"}, {"after", {"A"}}},
                                 {{"name", "C"}, {"after", {"B"}}}};
    EXPECT_EQ(contains(trace_error(capture(loop, one)), "the jobs form a cycle"), "");
    const nlohmann::json unknown = {{{"name", "A"}, {"after", {"Z"}}}};
    EXPECT_EQ(contains(trace_error(capture(unknown, one)), "names 'Z', which is not a job of the graph"), "");
    const nlohmann::json twice = {{{"name", "A"}, {"after", nlohmann::json::array()}},
                                  {{"name", "A"}, {"after", nlohmann::json::array()}}};
    EXPECT_EQ(contains(trace_error(capture(twice, one)), "listed twice"), "");

    EXPECT_EQ(contains(trace_error(capture(ok_jobs, nlohmann::json::array({zone("A", 2147483647, 0)}))),
                       "traceEvents[0].args.frame must be an integer in [0, 1000000000], got 2147483647"),
              "");
    EXPECT_EQ(contains(trace_error(capture(ok_jobs, nlohmann::json::array({zone("A", 1e30, 0)}))),
                       "args.frame must be an integer"),
              "");
    EXPECT_EQ(contains(trace_error(capture(ok_jobs, nlohmann::json::array({zone("A", 0, 1e30)}))),
                       "traceEvents[0].tid must be an integer"),
              "");
    EXPECT_EQ(
        contains(trace_error(capture(ok_jobs, nlohmann::json::array({zone("A", -1, 0)}))), "args.frame"), "");
    nlohmann::json bad_time = zone("A", 0, 0);
    bad_time["dur"] = -5;
    EXPECT_EQ(contains(trace_error(capture(ok_jobs, nlohmann::json::array({bad_time}))),
                       "traceEvents[0].dur must be a number"),
              "");
    bad_time["dur"] = "soon";
    EXPECT_EQ(
        contains(trace_error(capture(ok_jobs, nlohmann::json::array({bad_time}))), "traceEvents[0].dur"), "");
}

TEST(HostileInput, TraceSummaryCommandNamesTheFileAndTheProblem) {
    const std::string path = temp_path("cyclic-trace.json");
    write_text(path,
               capture({{{"name", "A"}, {"after", {"A"}}}}, nlohmann::json::array({zone("A", 0, 0)})).dump());
    expect_one_error_line(run_cli("trace-summary " + path), path + ": otherData.jobs: the jobs form a cycle");
}
