// Scene files: every built-in scene survives a round trip through JSON, a file can start from a built-in
// scene, and mistakes (unknown keys, wrong types, out-of-range numbers) are errors that name the key.
#include <gtest/gtest.h>

#include "support/test_support.h"
#include "systems/scenes/frame_inputs.h"
#include "systems/scenes/scene_json.h"

using namespace rivulet;

namespace {

std::string error_of(const std::string& text) {
    try {
        scene_from_json(nlohmann::json::parse(text), "test.json");
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST(SceneJson, BuiltinScenesRoundTripExactly) {
    for (std::string_view name : builtin_scene_names()) {
        const SceneDesc s = make_builtin_scene(name);
        const nlohmann::json j = scene_to_json(s);
        const SceneDesc back = scene_from_json(j, "roundtrip");
        EXPECT_EQ(scene_to_json(back), j) << name;
        EXPECT_EQ(back.emitters.size(), s.emitters.size());
        EXPECT_EQ(back.particle_radius, s.particle_radius);  // floats survive bit for bit
        EXPECT_EQ(back.pool.impulse_scale, s.pool.impulse_scale);
    }
}

TEST(SceneJson, AFileStartsFromABuiltinSceneAndOverridesFields) {
    const std::string path = test::temp_path("scene.json");
    test::write_text(path, R"({"base": "faucet", "name": "my faucet", "seed": 99,
                               "emitters": [{"position": [0, 1, 0], "rate": 500}],
                               "pool": {"level": 0.3}})");
    const SceneDesc s = resolve_scene(path);
    const SceneDesc faucet = make_builtin_scene("faucet");
    EXPECT_EQ(s.name, "my faucet");
    EXPECT_EQ(s.seed, 99u);
    ASSERT_EQ(s.emitters.size(), 1u);
    EXPECT_EQ(s.emitters[0].rate, 500.0f);
    EXPECT_EQ(s.emitters[0].position.y, 1.0f);
    EXPECT_EQ(s.emitters[0].speed, Emitter{}.speed);  // a new emitter starts from the defaults
    EXPECT_EQ(s.pool.level, 0.3f);
    EXPECT_EQ(s.pool.nx, faucet.pool.nx);  // untouched fields keep the base scene's values
    EXPECT_EQ(s.camera.fov_y_deg, faucet.camera.fov_y_deg);
}

TEST(SceneJson, MistakesNameTheKey) {
    EXPECT_NE(error_of(R"({"partcle_radius": 0.1})").find("test.json.partcle_radius: unknown key"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"pool": {"nx": "many"}})").find("test.json.pool.nx: expected an integer"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"gravity": [0, -9.8]})").find("test.json.gravity: expected [x, y, z]"),
              std::string::npos);
    EXPECT_NE(error_of(R"({"dt": 1e300})").find("test.json.dt: expected a finite number"), std::string::npos);
    EXPECT_NE(
        error_of(R"({"gravity": [0, -1e9, 0]})").find("gravity must be finite, each component within 1e4"),
        std::string::npos);
    EXPECT_NE(error_of(R"({"max_particles": -5})").find("non-negative"), std::string::npos);
    EXPECT_NE(error_of(R"({"base": "lake"})").find("unknown scene 'lake'"), std::string::npos);
    EXPECT_NE(error_of(R"([1, 2])").find("one JSON object"), std::string::npos);
    EXPECT_NE(error_of(R"({"base": "dambreak", "sph": {"solver": "pcisph"}})")
                  .find("test.json.sph.solver: expected \"dfsph\" or \"wcsph\""),
              std::string::npos);
}

TEST(SceneJson, SphSceneChoosesItsPressureSolver) {
    const SceneDesc dambreak = make_builtin_scene("dambreak");
    EXPECT_EQ(dambreak.sph.solver, SphSolver::kDfsph);  // the built-in SPH scenes' default
    EXPECT_EQ(scene_to_json(dambreak)["sph"]["solver"], "dfsph");
    const std::string path = test::temp_path("wcsph.json");
    test::write_text(path, R"({"base": "dambreak", "sph": {"solver": "wcsph", "max_density_error": 0.5}})");
    const SceneDesc s = resolve_scene(path);
    EXPECT_EQ(s.sph.solver, SphSolver::kWcsph);
    EXPECT_EQ(s.sph.max_density_error, 0.5f);
    EXPECT_EQ(s.sph.spacing, dambreak.sph.spacing);
}

TEST(SceneJson, AShakeFasterThanTheSubstepsCanFollowIsRefused) {
    // The dam break follows its tank up to 132 m/s (sph_max_tank_speed): 0.3 m at 50 Hz moves it 36 m/s
    // over a frame, 3 m at 50 Hz 360 m/s.
    EXPECT_EQ(
        error_of(R"({"base": "dambreak", "container_motion": {"amplitude": [0.3, 0, 0], "frequency": 50}})"),
        "no error");
    EXPECT_NE(
        error_of(R"({"base": "dambreak", "container_motion": {"amplitude": [3, 0, 0], "frequency": 50}})")
            .find("container_motion moves the tank at up to"),
        std::string::npos);
    EXPECT_NE(
        error_of(R"({"base": "dambreak", "container_motion": {"amplitude": [1e9, 0, 0], "frequency": 1}})")
            .find("raise sph.max_substeps"),
        std::string::npos);
}

TEST(SceneJson, ContainerMotionScriptsASineOffset) {
    SceneDesc s = make_builtin_scene("faucet");
    s.dt = 0.01f;
    s.container_motion = {{0.1f, 0, 0}, 1.0f};  // 1 Hz: a quarter period is 25 frames
    // The offset is the container's pose at the end of the frame: t = (frame + 1) dt.
    EXPECT_NEAR(scripted_inputs(s, 24).container_offset.x, 0.1f, 1e-6f);
    EXPECT_NEAR(scripted_inputs(s, 49).container_offset.x, 0.0f, 1e-6f);
    EXPECT_NEAR(scripted_inputs(s, 74).container_offset.x, -0.1f, 1e-6f);
    EXPECT_EQ(scripted_inputs(s, 24).emitter_scale, 1.0f);
}
