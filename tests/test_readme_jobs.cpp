// README.md's job list against the frame graphs themselves (FrameGraph::job_name): every job a pipeline
// builds is named there and every job named there exists, parallel ones marked "name*", so the list
// cannot go stale. `rivulet run --graph FILE.dot` draws any one graph.
#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "runtime/lib/frame_pipeline.h"
#include "support/test_support.h"
#include "systems/scenes/scene.h"

using namespace rivulet;

namespace {

// Job name -> parallel, over the pipelines of every kind of simulation and every surface method.
std::map<std::string, bool> pipeline_jobs() {
    std::map<std::string, bool> jobs;
    const auto add = [&jobs](SceneDesc scene, SurfaceMethod method, float anisotropy = 0.0f,
                             CylinderAxis axis = CylinderAxis::kPath) {
        PipelineSettings config;
        config.method = method;
        config.scan.axis = axis;
        config.slices.anisotropy = anisotropy;
        config.render = false;
        FramePipeline pipeline(scene, config);
        const FrameGraph& g = pipeline.graph();
        for (FrameGraph::JobId j = 0; j < g.job_count(); ++j)
            jobs[g.job_name(j)] = g.job_parallel(j) && g.job_parent(j) < 0;
    };
    for (SurfaceMethod m :
         {SurfaceMethod::kScan, SurfaceMethod::kSlices, SurfaceMethod::kScreen, SurfaceMethod::kVolume})
        add(make_builtin_scene("fountain"), m, 0.0f);
    add(make_builtin_scene("fountain"), SurfaceMethod::kSlices, kDefaultAnisotropy);
    add(make_builtin_scene("fountain"), SurfaceMethod::kScan, 0.0f, CylinderAxis::kVertical);
    add(make_builtin_scene("faucet"), SurfaceMethod::kHybrid);
    SceneDesc dam = make_builtin_scene("dambreak");
    add(dam, SurfaceMethod::kScan);
    add(dam, SurfaceMethod::kHybrid);  // the largest graph: SPH, the oriented jobs and slices'
    dam.sph.solver = SphSolver::kWcsph;
    add(dam, SurfaceMethod::kScan);
    add(make_builtin_scene("ghost"), SurfaceMethod::kSprites);
    return jobs;
}

// The names in README.md's job list (the code block from "simulation (" to "(* = items run in parallel)"),
// with whether each is marked "*". File names (jobs/bin_sort.h, ...) are not job names.
std::map<std::string, bool> readme_jobs(std::string& block) {
    std::ifstream in(std::string(RIVULET_SOURCE_DIR) + "/README.md");
    std::stringstream text;
    text << in.rdbuf();
    const std::string readme = text.str();
    const std::size_t begin = readme.find("\nsimulation ("), end = readme.find("(* = items run in parallel)");
    if (begin == std::string::npos || end == std::string::npos || end < begin) return {};
    block = readme.substr(begin, end - begin);
    std::map<std::string, bool> names;
    const std::regex token(R"(([A-Za-z0-9_/]*[a-z_]+(\.[a-z_0-9]+)+)(\*?))");
    for (auto it = std::sregex_iterator(block.begin(), block.end(), token); it != std::sregex_iterator();
         ++it) {
        const std::string name = (*it)[1];
        if (name.find('/') != std::string::npos || name.ends_with(".h") || name.ends_with(".cpp")) continue;
        names[name] = names[name] || (*it)[3].length() > 0;
    }
    return names;
}

}  // namespace

TEST(ReadmeJobs, TheListNamesEveryJobOfEveryPipelineAndNoOther) {
    const std::map<std::string, bool> graph = pipeline_jobs();
    std::string block;
    const std::map<std::string, bool> readme = readme_jobs(block);
    ASSERT_FALSE(readme.empty()) << "README.md has no job list";
    ASSERT_GT(graph.size(), 40u);
    for (const auto& [name, parallel] : graph) {
        if (name.find('.') == std::string::npos) {  // the pipeline's own jobs, e.g. upload_staging
            EXPECT_TRUE(std::regex_search(block, std::regex("\\b" + name + "\\b")))
                << name << " is not in README.md";
            continue;
        }
        const auto it = readme.find(name);
        if (it == readme.end()) {
            ADD_FAILURE() << name << " is not in README.md's job list";
            continue;
        }
        if (parallel) {
            EXPECT_TRUE(it->second) << name << " runs items in parallel: README.md should say " << name
                                    << "*";
        }
    }
    for (const auto& [name, parallel] : readme)
        EXPECT_TRUE(graph.count(name)) << "README.md names a job no pipeline has: " << name;
}

TEST(ReadmeJobs, RunWritesTheGraphAsDot) {
    const std::string dot = test::temp_path("graph.dot");
    const test::Result r =
        test::run_cli("run --scene fountain --method slices --frames 1 --no-render --graph " + dot);
    ASSERT_EQ(r.status, 0) << r.output;
    std::ifstream in(dot);
    std::stringstream text;
    text << in.rdbuf();
    const std::string g = text.str();
    EXPECT_TRUE(g.starts_with("digraph frame {"));
    EXPECT_NE(g.find("label=\"slices.blocks*\""), std::string::npos);
    EXPECT_NE(g.find("label=\"simulate.begin\""), std::string::npos);
    EXPECT_NE(g.find(" -> "), std::string::npos);
    EXPECT_TRUE(g.ends_with("}\n"));
}
