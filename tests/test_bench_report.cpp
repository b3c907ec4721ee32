// The bench report: speedup and efficiency against the fewest threads of each scene and method, the
// Markdown table, and plots actually drawn by `rivulet bench`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "runtime/lib/bench_report.h"
#include "support/test_support.h"

using namespace rivulet;

namespace {

BenchCase make_case(const char* scene, int threads, double frame_ms) {
    BenchCase c{scene, "scan", threads, {}};
    c.run["frame_ms"] = frame_ms;
    c.run["extract_ms"] = frame_ms / 2;
    c.run["render_ms"] = frame_ms / 2;
    c.run["stages"] = {{"scan.deform", 1.0}, {"scan.normals", 0.5}};
    return c;
}

bool is_png(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    char sig[8] = {};
    f.read(sig, 8);
    return f && std::string(sig + 1, 3) == "PNG";
}

}  // namespace

TEST(BenchReport, SpeedupAndEfficiencyAgainstTheFewestThreads) {
    std::vector<BenchCase> cases = {make_case("a", 2, 10.0), make_case("a", 1, 16.0), make_case("a", 4, 8.0),
                                    make_case("b", 2, 5.0)};
    derive_scaling(cases);
    EXPECT_DOUBLE_EQ(cases[1].speedup, 1.0);
    EXPECT_DOUBLE_EQ(cases[0].frames_per_second, 100.0);
    EXPECT_DOUBLE_EQ(cases[0].speedup, 1.6);
    EXPECT_DOUBLE_EQ(cases[0].efficiency, 0.8);
    EXPECT_DOUBLE_EQ(cases[2].speedup, 2.0);
    EXPECT_DOUBLE_EQ(cases[2].efficiency, 0.5);
    EXPECT_DOUBLE_EQ(cases[3].speedup, 1.0);  // b has only 2 threads: its own base
    const std::string md = bench_markdown(cases, {{"description", "test"}});
    EXPECT_NE(md.find("| a | scan | 4 | 8.00 | 125.0 | 2.00 | 50 % |"), std::string::npos) << md;

    std::vector<BenchCase> broken = {make_case("a", 1, 0.0)};
    EXPECT_THROW(derive_scaling(broken), std::invalid_argument);
}

TEST(BenchReport, BenchCommandWritesJsonTableAndPlots) {
    const std::string out = test::temp_path("bench");
    const test::Result r = test::run_cli(
        "bench --scenes faucet --threads 1,2 --frames 2 --timing-warmup 1 "
        "--no-render --out " +
        out);
    ASSERT_EQ(r.status, 0) << r.output;
    const nlohmann::json j = test::read_json(out + "/bench.json");
    ASSERT_EQ(j["cases"].size(), 2u);
    EXPECT_EQ(j["cases"][0]["threads"], 1);
    EXPECT_EQ(j["cases"][1]["threads"], 2);
    EXPECT_EQ(j["cases"][0]["frames"], 2);  // timed frames only
    EXPECT_GT(j["cases"][1]["frames_per_second"].get<double>(), 0.0);
    EXPECT_TRUE(j["cases"][1]["stages"].contains("oriented.skeleton"));
    EXPECT_TRUE(std::filesystem::exists(out + "/bench.md"));
    EXPECT_TRUE(is_png(out + "/scaling.png"));
    EXPECT_TRUE(is_png(out + "/stages.png"));

    const test::Result bad = test::run_cli("bench --threads 1,x --out " + out);
    EXPECT_NE(bad.status, 0);
    EXPECT_NE(bad.output.find("'x' is not a count"), std::string::npos) << bad.output;
}
