// `rivulet mesh --method volume` as users' scripts see it: a marching-cubes mesh of the density volume,
// the volume as an OpenVDB file, the same bytes at 1 and 2 threads, and bad input rejected with a clear
// message and a non-zero exit; the AVX2 and baseline splats give the same bytes.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "jobs/counter_rng.h"
#include "jobs/cpu_dispatch.h"
#include "support/test_support.h"
#include "systems/io/mesh_io.h"

namespace {

using rivulet::test::read_json;
using rivulet::test::Result;
using rivulet::test::run_cli;
using rivulet::test::temp_path;
using rivulet::test::write_text;

// A cube of n^3 particles of spacing 2 radius (radius 0.05) from the origin.
std::string lattice_xyz(int n) {
    std::string text = "# lattice\n";
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                text += std::to_string(0.1 * i) + " " + std::to_string(0.1 * j) + " " +
                        std::to_string(0.1 * k) + "\n";
    return text;
}

}  // namespace

TEST(VolumeCli, MeshOfALatticeIsItsBoxOneRadiusOut) {
    const std::string in = temp_path("lattice.xyz"), ply = temp_path("lattice_volume.ply"),
                      json = temp_path("volume.json");
    write_text(in, lattice_xyz(8));
    const Result r =
        run_cli("mesh " + in + " --method volume --radius 0.05 --threads 2 --out " + ply + " --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json);
    EXPECT_EQ(j["method"], "volume");
    EXPECT_EQ(j["particles"], 512);
    EXPECT_GT(j["bricks"].get<int>(), 0);
    EXPECT_FLOAT_EQ(j["kernel_radius"].get<float>(), 0.2f) << "h = 4 radii";
    for (const char* stage : {"volume.bounds", "volume.bin_count", "volume.splat", "volume.mesh"})
        EXPECT_TRUE(j["stages"].contains(stage)) << stage;
    // The flat faces of the lattice's box lie about one radius outside the outermost centres: the mesh's
    // bounds are the box [0, 0.7]^3 grown by 0.05, within a voxel.
    const rivulet::MeshData mesh = rivulet::read_mesh(ply);
    ASSERT_GT(mesh.triangle_count(), 100u);
    float lo[3] = {1e9f, 1e9f, 1e9f}, hi[3] = {-1e9f, -1e9f, -1e9f};
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        for (int a = 0; a < 3; ++a) {
            const float p = mesh.vertices6[6 * v + a];
            lo[a] = std::min(lo[a], p), hi[a] = std::max(hi[a], p);
        }
    const float voxel = j["voxel"].get<float>();
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(lo[a], -0.05f, voxel) << a;
        EXPECT_NEAR(hi[a], 0.75f, voxel) << a;
    }
    // One thread: the same bytes.
    const std::string json1 = temp_path("volume1.json");
    ASSERT_EQ(run_cli("mesh " + in + " --method volume --radius 0.05 --threads 1 --json " + json1).status, 0);
    EXPECT_EQ(read_json(json1)["mesh_hash"], j["mesh_hash"]);
}

// The splat runs an AVX2 build (eight samples of a row at a time) where the CPU has it: the same volume,
// so the same mesh bytes, as the baseline build's, with kernels spanning 8, 4 and 2.5 voxels (rows of
// up to 17, 9 and 6 samples: three, two and one 8-wide vectors).
TEST(VolumeCli, Avx2AndBaselineSplatsGiveTheSameBytes) {
    if (!rivulet::cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU (or RIVULET_NO_AVX2 is set)";
    std::string text;
    for (std::uint32_t i = 0; i < 3000; ++i)
        text += std::to_string(0.6f * rivulet::counter_uniform(11, 0, i, 0)) + " " +
                std::to_string(0.3f * rivulet::counter_uniform(11, 0, i, 1)) + " " +
                std::to_string(0.4f * rivulet::counter_uniform(11, 0, i, 2)) + "\n";
    const std::string in = temp_path("avx2_cloud.xyz");
    write_text(in, text);
    for (const char* voxel : {"0.01", "0.02", "0.032"}) {
        std::string hash[2];
        for (int baseline = 0; baseline < 2; ++baseline) {
            const std::string json =
                temp_path(std::string("avx2_") + voxel + (baseline ? "_base" : "") + ".json");
            const Result r = run_cli("mesh " + in + " --method volume --radius 0.02 --voxel " + voxel +
                                         " --threads 2 --json " + json,
                                     baseline ? "RIVULET_NO_AVX2=1" : "");
            ASSERT_EQ(r.status, 0) << r.output;
            hash[baseline] = read_json(json)["mesh_hash"].get<std::string>();
            EXPECT_GT(read_json(json)["triangles"].get<int>(), 1000);
        }
        EXPECT_EQ(hash[0], hash[1]) << "voxel " << voxel;
    }
}

TEST(VolumeCli, WritesAnOpenVdbFile) {
    const std::string in = temp_path("lattice_vdb.xyz"), vdb = temp_path("lattice.vdb");
    write_text(in, lattice_xyz(4));
    const Result r = run_cli("mesh " + in + " --method volume --radius 0.05 --level-set --out " + vdb);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("volume_hash"), std::string::npos) << r.output;
    ASSERT_TRUE(std::filesystem::exists(vdb));
    EXPECT_GT(std::filesystem::file_size(vdb), 1000u);
}

TEST(VolumeCli, BadOptionsAreClearErrors) {
    const std::string in = temp_path("lattice_bad.xyz");
    write_text(in, lattice_xyz(3));
    const auto fails_with = [&](const std::string& args, const std::string& text) {
        const Result r = run_cli("mesh " + in + " " + args);
        EXPECT_NE(r.status, 0) << args;
        EXPECT_NE(r.output.find(text), std::string::npos) << args << "\n" << r.output;
    };
    fails_with("--method volume --radius 0.05 --voxel 0.0001", "--max-dim");
    fails_with("--method volume --radius 0.05 --max-dim 100", "--max-dim");
    fails_with("--method volume --radius 0.05 --kernel 0", "--kernel");
    fails_with("--method slices --radius 0.05 --out " + temp_path("x.vdb"), "--method volume");
    fails_with("--method volume --radius 0.05 --level-set --out " + temp_path("x.ply"), "--level-set");
    const std::string empty = temp_path("empty.xyz");
    write_text(empty, "# no particles\n");
    const Result none = run_cli("mesh " + empty + " --method volume --radius 0.05");
    EXPECT_NE(none.status, 0);
    EXPECT_NE(none.output.find("empty.xyz"), std::string::npos) << none.output;
    const std::string nan = temp_path("nan.xyz");
    write_text(nan, "0 0 0\nnan 0 0\n0.1 0 0\n");
    const Result r = run_cli("mesh " + nan + " --method volume --radius 0.05");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("non-finite"), std::string::npos) << r.output;
}

TEST(VolumeCli, RunRecordsAndReplaysTheVolumeWithItsSettings) {
    const std::string rec = temp_path("volume.rivrec");
    const Result r = run_cli(
        "run --scene faucet --method volume --frames 4 --threads 2 --no-render --kernel 5 "
        "--max-dim 64 --record " +
        rec);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("bricks"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("volume.splat"), std::string::npos) << r.output;
    const auto doc = read_json(rec);
    EXPECT_EQ(doc["method"], "volume");
    EXPECT_EQ(doc["settings"]["kernel_radii"].get<float>(), 5.0f);
    EXPECT_EQ(doc["settings"]["max_dim"].get<int>(), 64);
    const Result replay = run_cli("replay " + rec + " --threads 1");
    EXPECT_EQ(replay.status, 0) << replay.output;
}
