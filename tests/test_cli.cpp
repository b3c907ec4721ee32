// The command line as users' scripts see it (DESIGN §4): JSON keys, exit codes, clear errors.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "support/test_support.h"
#include "systems/io/mesh_io.h"
#include "systems/io/particle_io.h"

namespace {

using rivulet::test::read_json;
using rivulet::test::Result;
using rivulet::test::run_cli;
using rivulet::test::write_text;

}  // namespace

TEST(Cli, RunWritesTheTimingJsonAndPictures) {
    const std::string json = rivulet::test::temp_path("run.json"), out = rivulet::test::temp_path("frames");
    const Result r =
        run_cli("run --frames 3 --threads 2 --size 160x90 --warmup 20 --out " + out + " --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("frames/s"), std::string::npos);
    const auto j = read_json(json);
    EXPECT_EQ(j["frames"], 3);
    for (const char* key : {"frame_ms", "render_ms", "extract_ms"})
        EXPECT_GT(j[key].get<double>(), 0.0) << key;
    for (const char* stage :
         {"oriented.link", "oriented.skeleton", "oriented.rings", "oriented.normals", "upload_staging"})
        EXPECT_TRUE(j["stages"].contains(stage)) << stage;
    EXPECT_TRUE(std::ifstream(out + "/frame_00002.png").good());
}

// An SPH run reports its solver's work and the density error it left, on the console and in --json.
TEST(Cli, SphRunReportsSubstepsIterationsAndTheDensityError) {
    const std::string json = rivulet::test::temp_path("sph.json");
    const Result r = run_cli("run --scene " + std::string(RIVULET_SOURCE_DIR) +
                             "/tests/golden/dambreak_small.json --frames 12 --threads 2 --no-render "
                             "--method slices --json " +
                             json);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("sph dfsph: substeps per frame median"), std::string::npos) << r.output;
    const auto sph = read_json(json)["sph"];
    EXPECT_EQ(sph["solver"], "dfsph");
    EXPECT_GE(sph["substeps_median"].get<int>(), 1);
    EXPECT_GE(sph["iterations_max"].get<int>(), sph["iterations_median"].get<int>());
    EXPECT_GT(sph["density_error_max_percent"].get<double>(), 0.0);
    EXPECT_LE(sph["density_error_max_percent"].get<double>(), 0.1 + 1e-6);
}

TEST(Cli, MeshWritesAMeshAndItsJson) {
    const std::string in = rivulet::test::temp_path("column.xyz"),
                      obj = rivulet::test::temp_path("column.obj"),
                      json = rivulet::test::temp_path("mesh.json");
    std::string text = "# a vertical column\n";
    for (int i = 0; i < 50; ++i) text += "0 " + std::to_string(0.01 * i) + " 0\n";
    write_text(in, text);
    const Result r = run_cli("mesh " + in + " --method scan --radius 0.03 --repeat 3 --threads 2 --out " +
                             obj + " --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json);
    EXPECT_EQ(j["particles"], 50);
    EXPECT_GT(j["triangles"].get<int>(), 0);
    EXPECT_GT(j["vertices"].get<int>(), 0);
    EXPECT_EQ(j["mesh_hash"].get<std::string>().size(), 16u);
    EXPECT_TRUE(j["stages"].contains("oriented.skeleton"));
    EXPECT_GE(j["total_ms"].get<double>(), 0.0);
    // Same input, other thread count: same bytes.
    const std::string json1 = rivulet::test::temp_path("mesh1.json");
    ASSERT_EQ(run_cli("mesh " + in + " --radius 0.03 --threads 1 --json " + json1).status, 0);
    EXPECT_EQ(read_json(json1)["mesh_hash"], j["mesh_hash"]);
}

TEST(Cli, MeshRunsOverANumberedSequence) {
    const std::string dir = rivulet::test::temp_path("sequence");
    std::filesystem::create_directories(dir);
    for (int f : {1, 2, 10}) {  // numeric order, not text order
        std::string text;
        for (int i = 0; i < 30; ++i)
            text += std::to_string(0.01 * f) + " " + std::to_string(0.01 * i) + " 0\n";
        write_text(dir + "/frame_" + std::to_string(f) + ".xyz", text);
    }
    const std::string json = dir + "/seq.json";
    const Result r = run_cli("mesh '" + dir + "/frame_{}.xyz' --radius 0.02 --radial gaussian --out '" + dir +
                             "/out_{}.ply' --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json);
    ASSERT_EQ(j["frames"].size(), 3u);
    EXPECT_NE(j["frames"][2]["input"].get<std::string>().find("frame_10.xyz"), std::string::npos);
    for (int f : {1, 2, 10}) {
        const rivulet::MeshData mesh = rivulet::read_mesh(dir + "/out_" + std::to_string(f) + ".ply");
        EXPECT_EQ(mesh.triangle_count(), j["frames"][0]["triangles"].get<std::size_t>()) << f;
    }
}

TEST(Cli, AFailedPictureWriteStopsTheRunWithAMessage) {
    // A directory where frame 1's picture should go: the encoder cannot open the file.
    const std::string out = rivulet::test::temp_path("blocked-frames");
    std::filesystem::create_directories(out + "/frame_00001.png");
    const Result r = run_cli("run --frames 4 --threads 2 --size 64x36 --warmup 5 --out " + out);
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("frame_00001.png"), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("terminate"), std::string::npos) << r.output;
}

TEST(Cli, BadInputsFailWithAClearMessage) {
    const std::string truncated = rivulet::test::temp_path("trunc.ply"),
                      nan = rivulet::test::temp_path("nan.xyz"),
                      empty = rivulet::test::temp_path("empty.xyz");
    write_text(
        truncated,
        "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n1234");
    write_text(nan, "0 0 0\nnan 1 0\n");
    write_text(empty, "# nothing\n");
    struct Case {
        std::string args, expect;
    };
    for (const Case& c : std::vector<Case>{{"mesh " + truncated, "truncated"},
                                           {"mesh " + nan, "non-finite"},
                                           {"mesh " + empty, "no particles"},
                                           {"mesh /nonexistent/x.ply", "x.ply"},
                                           {"mesh " + nan + " --radius -1", "--radius"},
                                           {"mesh " + nan + " --u 1", "--u"},
                                           {"run --scene nope --frames 1", "nope"},
                                           {"run --frames 0", "--frames"},
                                           {"run --size 12x", "--size"},
                                           {"run --method blobs --frames 1", "blobs"},
                                           {"run --epsilon -1 --frames 1", "--epsilon"},
                                           {"run --warmup -3 --frames 1", "--warmup"},
                                           {"mesh " + nan + " --threads 5000", "--threads"},
                                           {"mesh " + nan + " --method voxels", "voxels"}}) {
        const Result r = run_cli(c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << " said: " << r.output;
    }
}
