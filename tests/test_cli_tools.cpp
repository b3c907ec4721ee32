// simulate, replay and scene files from the command line: the PLY sequence `simulate` writes is what
// `mesh` reads back; a scene file runs; bad arguments are clear errors.
#include <gtest/gtest.h>

#include <filesystem>

#include "support/test_support.h"
#include "systems/io/particle_io.h"

using rivulet::test::run_cli;

TEST(CliTools, SimulateWritesAPlySequenceThatMeshReadsBack) {
    const std::string dir = rivulet::test::temp_path("sim");
    const auto r = run_cli("simulate --scene faucet --frames 3 --warmup 20 --threads 2 --out " + dir);
    ASSERT_EQ(r.status, 0) << r.output;
    for (int i = 0; i < 3; ++i) {
        const auto cloud = rivulet::read_particles(dir + "/frame_0000" + std::to_string(i) + ".ply");
        EXPECT_GT(cloud.size(), 500u);
    }
    EXPECT_FALSE(std::filesystem::exists(dir + "/frame_00003.ply"));
    const std::string json = dir + "/mesh.json";
    const auto m = run_cli("mesh '" + dir + "/frame_{}.ply' --out '" + dir + "/mesh_{}.obj' --json " + json);
    ASSERT_EQ(m.status, 0) << m.output;
    EXPECT_TRUE(std::filesystem::exists(dir + "/mesh_00002.obj"));
}

TEST(CliTools, RunAcceptsASceneFile) {
    const std::string scene = rivulet::test::temp_path("tiny.json");
    rivulet::test::write_text(scene, R"({"base": "faucet", "name": "tiny", "warmup_frames": 5})");
    const auto r = run_cli("run --scene " + scene + " --frames 2 --no-render");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("scene tiny"), std::string::npos) << r.output;

    rivulet::test::write_text(scene, R"({"base": "faucet", "substeps": 0})");
    const auto bad = run_cli("run --scene " + scene + " --frames 2 --no-render");
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("substeps must be in [1, 64]"), std::string::npos) << bad.output;
}

TEST(CliTools, RunReportsACylinderPoolThatRanOut) {
    const auto r = run_cli("run --frames 2 --warmup 30 --no-render --max-groups 2");
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("the cylinder pool (--max-groups 2) ran out in 2 of 2 frames"), std::string::npos)
        << r.output;
    const auto ok = run_cli("run --frames 2 --warmup 30 --no-render");
    EXPECT_EQ(ok.output.find("ran out"), std::string::npos) << ok.output;
}

TEST(CliTools, BadArgumentsAreClearErrors) {
    auto r = run_cli("simulate --scene lake --frames 2 --out " + rivulet::test::temp_path("x"));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("unknown scene 'lake'"), std::string::npos) << r.output;
    r = run_cli("replay " + rivulet::test::temp_path("nothing.rivrec"));
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("cannot read recording: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("nothing.rivrec: cannot open: No such file"), std::string::npos) << r.output;
    r = run_cli("run --frames 3 --timing-warmup 3 --no-render");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.output.find("--timing-warmup (3) must be less than --frames (3)"), std::string::npos)
        << r.output;
}
