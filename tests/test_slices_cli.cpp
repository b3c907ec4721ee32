// `rivulet mesh --method slices` as users' scripts see it: JSON keys, mesh files, sequences, the same
// bytes at 1 and 2 threads, and bad input rejected with a clear message and a non-zero exit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "support/test_support.h"
#include "systems/io/mesh_io.h"
#include "systems/slices/slices_settings.h"

namespace {

using rivulet::test::read_json;
using rivulet::test::Result;
using rivulet::test::run_cli;
using rivulet::test::write_text;

// A blob of `n` particles around (cx, 0, 0).
std::string blob_xyz(int n, float cx, unsigned seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<float> g(0.0f, 0.06f);
    std::string text = "# blob\n";
    for (int i = 0; i < n; ++i)
        text +=
            std::to_string(cx + g(rng)) + " " + std::to_string(g(rng)) + " " + std::to_string(g(rng)) + "\n";
    return text;
}

}  // namespace

TEST(SlicesCli, MeshWritesAMeshAndItsJson) {
    const std::string in = rivulet::test::temp_path("blob.xyz"), obj = rivulet::test::temp_path("blob.obj"),
                      json = rivulet::test::temp_path("slices.json");
    write_text(in, blob_xyz(300, 0, 1));
    const Result r =
        run_cli("mesh " + in + " --method slices --radius 0.03 --repeat 3 --threads 2 --block 8 --out " +
                obj + " --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json);
    EXPECT_EQ(j["method"], "slices");
    EXPECT_EQ(j["particles"], 300);
    EXPECT_GT(j["triangles"].get<int>(), 100);
    EXPECT_GT(j["vertices"].get<int>(), 50);
    EXPECT_EQ(j["mesh_hash"].get<std::string>().size(), 16u);
    EXPECT_GE(j["total_ms"].get<double>(), 0.0);
    for (const char* stage : {"slices.begin", "slices.count", "slices.scatter", "slices.blocks",
                              "slices.weld", "slices.normals", "slices.borders", "slices.stage"})
        EXPECT_TRUE(j["stages"].contains(stage)) << stage;
    EXPECT_FLOAT_EQ(j["voxel"].get<float>(), 0.015f) << "default voxel: radius / 2";
    EXPECT_EQ(j["field"], "spacing");
    const float spacing = j["spacing"].get<float>();
    EXPECT_GT(spacing, 0.0f);
    EXPECT_FLOAT_EQ(j["rc"].get<float>(),
                    static_cast<float>(rivulet::spacing_field(double(spacing) / 0.03).rc_factor) * 0.03f);
    // Every triangle comes from a swept cube, at most five a cube; the sweep starts from seeds.
    EXPECT_GE(5 * j["cubes"].get<std::uint64_t>(), j["triangles"].get<std::uint64_t>());
    EXPECT_GT(j["seeds"].get<std::uint64_t>(), 0u);
    const rivulet::MeshData mesh = rivulet::read_mesh(obj);
    EXPECT_EQ(mesh.triangle_count(), j["triangles"].get<std::size_t>());
    // Other thread count: same bytes.
    const std::string json1 = rivulet::test::temp_path("slices1.json");
    ASSERT_EQ(
        run_cli("mesh " + in + " --method slices --radius 0.03 --block 8 --threads 1 --json " + json1).status,
        0);
    EXPECT_EQ(read_json(json1)["mesh_hash"], j["mesh_hash"]);
    // A dense blob holds no empty cavity: exhaustive seeds give the same mesh.
    const std::string json2 = rivulet::test::temp_path("slices2.json");
    ASSERT_EQ(
        run_cli("mesh " + in + " --method slices --radius 0.03 --block 8 --exhaustive-seeds --json " + json2)
            .status,
        0);
    EXPECT_EQ(read_json(json2)["triangles"], j["triangles"]);
    // The classic field: R_c two radii whatever the spacing.
    const std::string json3 = rivulet::test::temp_path("slices3.json");
    ASSERT_EQ(run_cli("mesh " + in + " --method slices --radius 0.03 --field classic --json " + json3).status,
              0);
    EXPECT_EQ(read_json(json3)["field"], "classic");
    EXPECT_FLOAT_EQ(read_json(json3)["rc"].get<float>(), 0.06f);
    EXPECT_NE(run_cli("mesh " + in + " --method slices --radius 0.03 --field fuzzy").status, 0);
}

TEST(SlicesCli, MeshRunsOverANumberedSequence) {
    const std::string dir = rivulet::test::temp_path("slices-sequence");
    std::filesystem::create_directories(dir);
    for (int f : {1, 2, 10})
        write_text(dir + "/frame_" + std::to_string(f) + ".xyz", blob_xyz(80, 0.01f * float(f), 3));
    const std::string json = dir + "/seq.json";
    const Result r = run_cli("mesh '" + dir + "/frame_{}.xyz' --method slices --radius 0.03 --out '" + dir +
                             "/out_{}.obj' --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json);
    ASSERT_EQ(j["frames"].size(), 3u);
    EXPECT_NE(j["frames"][2]["input"].get<std::string>().find("frame_10.xyz"), std::string::npos);
    for (int k = 0; k < 3; ++k) {
        const int f = std::array<int, 3>{1, 2, 10}[std::size_t(k)];
        const rivulet::MeshData mesh = rivulet::read_mesh(dir + "/out_" + std::to_string(f) + ".obj");
        EXPECT_EQ(mesh.triangle_count(), j["frames"][k]["triangles"].get<std::size_t>()) << f;
    }
}

TEST(SlicesCli, BadInputsFailWithAClearMessage) {
    const std::string truncated = rivulet::test::temp_path("s-trunc.ply"),
                      header = rivulet::test::temp_path("s-header.ply"),
                      nan = rivulet::test::temp_path("s-nan.xyz"),
                      empty = rivulet::test::temp_path("s-empty.xyz"),
                      good = rivulet::test::temp_path("s-good.xyz");
    write_text(
        truncated,
        "ply\nformat binary_little_endian 1.0\nelement vertex 100\nproperty float x\nproperty float y\n"
        "property float z\nend_header\n1234");
    write_text(header, "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nend_header\n0\n1\n");
    write_text(nan, "0 0 0\nnan 1 0\n");
    write_text(empty, "# nothing\n");
    write_text(good, blob_xyz(20, 0, 5));
    struct Case {
        std::string args, expect;
    };
    const std::string m = " --method slices --radius 0.03";
    for (const Case& c : std::vector<Case>{{"mesh " + truncated + m, "truncated"},
                                           {"mesh " + header + m, "s-header.ply"},
                                           {"mesh " + nan + m, "non-finite"},
                                           {"mesh " + empty + m, "no particles"},
                                           {"mesh /nonexistent/x.ply" + m, "x.ply"},
                                           {"mesh " + good + m + " --voxel 1", "--voxel"},
                                           {"mesh " + good + m + " --voxel -1", "--voxel"},
                                           {"mesh " + good + m + " --block 1", "--block"},
                                           {"mesh " + good + " --method marching", "marching"}}) {
        const Result r = run_cli(c.args);
        EXPECT_NE(r.status, 0) << c.args;
        EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << " said: " << r.output;
        EXPECT_EQ(r.output.find("terminate"), std::string::npos) << c.args;
    }
}

TEST(SlicesCli, AnisotropicKernelsAreAnOptionWithItsRangeChecked) {
    const std::string in = rivulet::test::temp_path("aniso.xyz"),
                      json = rivulet::test::temp_path("aniso.json"),
                      round = rivulet::test::temp_path("round.json");
    write_text(in, blob_xyz(400, 0, 4));
    ASSERT_EQ(run_cli("mesh " + in + " --method slices --radius 0.03 --json " + round).status, 0);
    const Result r = run_cli("mesh " + in + " --method slices --radius 0.03 --anisotropic --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json), spheres = read_json(round);
    EXPECT_EQ(j["anisotropy"], rivulet::kDefaultAnisotropy);
    EXPECT_EQ(spheres["anisotropy"], 0);
    EXPECT_NE(j["mesh_hash"], spheres["mesh_hash"]);
    ASSERT_EQ(run_cli("mesh " + in +
                      " --method slices --radius 0.03 --anisotropic=2 --anisotropic-smoothing 0.5 "
                      "--json " +
                      json)
                  .status,
              0);
    EXPECT_EQ(read_json(json)["anisotropy"], 2);
    EXPECT_EQ(read_json(json)["anisotropy_smoothing"], 0.5);
    for (const std::string bad : {"--anisotropic=5", "--anisotropic=0.5", "--anisotropic-smoothing 2"}) {
        const Result e = run_cli("mesh " + in + " --method slices --radius 0.03 " + bad);
        EXPECT_NE(e.status, 0) << bad;
        EXPECT_NE(e.output.find("rivulet: error:"), std::string::npos) << bad << ": " << e.output;
    }
}

TEST(SlicesCli, MeshSmoothsKeepingTheVolumeAndReportsTriangleQuality) {
    const std::string in = rivulet::test::temp_path("smooth.xyz"),
                      json = rivulet::test::temp_path("smooth.json"),
                      raw = rivulet::test::temp_path("raw.json");
    write_text(in, blob_xyz(400, 0, 4));
    ASSERT_EQ(run_cli("mesh " + in + " --method slices --radius 0.03 --json " + raw).status, 0);
    const Result r = run_cli("mesh " + in + " --method slices --radius 0.03 --smooth 8 --json " + json);
    ASSERT_EQ(r.status, 0) << r.output;
    const auto j = read_json(json), before = read_json(raw);
    EXPECT_EQ(j["smoothing"]["iterations"], 8);
    EXPECT_EQ(j["smoothing"]["weights"], "particles") << "Löschner's weights by default";
    EXPECT_NEAR(j["smoothing"]["volume_after"].get<double>() / j["smoothing"]["volume_before"].get<double>(),
                1.0, 0.01);
    EXPECT_EQ(j["triangles"], before["triangles"]) << "smoothing keeps the topology";
    EXPECT_NE(j["mesh_hash"], before["mesh_hash"]);
    EXPECT_GT(j["quality"]["min_angle_p05_deg"].get<double>(),
              before["quality"]["min_angle_p05_deg"].get<double>());
    EXPECT_FALSE(before.contains("smoothing"));
    EXPECT_NE(run_cli("mesh " + in + " --method slices --radius 0.03 --smooth -1").status, 0);
    EXPECT_NE(
        run_cli("mesh " + in + " --method slices --radius 0.03 --smooth 2 --smooth-weights some").status, 0);
    const std::string plain = rivulet::test::temp_path("plain.json");
    ASSERT_EQ(run_cli("mesh " + in +
                      " --method slices --radius 0.03 --smooth 8 --smooth-weights none --json " + plain)
                  .status,
              0);
    EXPECT_NE(read_json(plain)["mesh_hash"], j["mesh_hash"]);
}
