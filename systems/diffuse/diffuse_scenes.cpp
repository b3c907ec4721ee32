// Diffuse objects after "Rendering diffuse objects using particle systems inside voxelized surface
// geometry" (Juckel & Beckhaus): a ghost that swirls and re-forms after a ball passes through it, a bunny
// blown away by the wind, a fire made of one voxel, and the paper's fluffy bunny (Figure 8).
#include "systems/diffuse/diffuse_scenes.h"

#include <array>
#include <stdexcept>
#include <string>

namespace rivulet {
namespace {

constexpr std::array<std::string_view, 4> kNames = {"ghost", "dissolve", "fire", "bunny"};

SceneDesc diffuse_base(const char* name) {
    SceneDesc s;
    s.name = name;
    s.simulation = SimulationKind::kDiffuse;
    s.gravity = {0, 0, 0};
    s.restitution = 0.5f;
    s.warmup_frames = 60;
    s.seed = 7;
    s.pool.enabled = false;
    return s;
}

// About 40,000 particles in a 50^3 grid, as the paper's Marvin. The head turns in a spiral, the hem
// rises in a helix, and a ball crosses the body every four seconds; the shape forms again behind it.
SceneDesc ghost() {
    SceneDesc s = diffuse_base("ghost");
    s.max_particles = 60000;
    s.camera = {{0.0f, 1.05f, 3.3f}, {0.0f, 0.85f, 0.0f}, 40.0f};
    s.container_motion = {{0.08f, 0.0f, 0.0f}, 0.25f};
    DiffuseDesc& d = s.diffuse;
    d.mesh = "ghost";
    d.resolution = 50;
    d.defaults.max_density = 6;
    d.defaults.size = 0.05f;
    d.defaults.alpha = 0.08f;
    d.defaults.fade_size = 0.09f;
    d.defaults.lifetime = 0.8f;
    d.defaults.drag = 3;
    d.defaults.jitter = 0.08f;
    DiffuseRegion head;
    head.shape = "sphere";
    head.center = {0, 1.35f, 0};
    head.radius = 0.3f;
    head.attributes.force = "spiral";
    head.attributes.force_vector = {0, 1, 0};
    head.attributes.force_rate = 1.6f;
    head.attributes.force_pull = 0.05f;
    head.attributes.about_region = true;
    DiffuseRegion hem;
    hem.shape = "box";
    hem.min = {-1, -0.1f, -1};
    hem.max = {1, 0.45f, 1};
    hem.attributes.force = "helix";
    hem.attributes.force_vector = {0, 1, 0};
    hem.attributes.force_rate = 2.5f;
    hem.attributes.force_pull = 0.12f;
    hem.attributes.about_region = true;
    hem.attributes.color = {0.55f, 0.8f, 1.0f};
    hem.attributes.alpha = 0.07f;
    d.regions = {hem, head};
    DiffuseCollider ball;
    ball.shape = "sphere";
    ball.radius = 0.2f;
    ball.from = {-1.6f, 0.95f, 0.05f};
    ball.to = {1.6f, 0.95f, 0.05f};
    ball.period = 8.0f;
    d.colliders = {ball};
    return s;
}

// The bunny forms, then from 2.5 s (1.5 s into the pictures) a wind front crosses it from the left and blows
// it away.
SceneDesc dissolve() {
    SceneDesc s = diffuse_base("dissolve");
    s.max_particles = 80000;
    s.camera = {{0.1f, 0.55f, 1.9f}, {0.1f, 0.35f, 0.0f}, 40.0f};
    DiffuseDesc& d = s.diffuse;
    d.mesh = "bunny";
    d.scale = 1.4f;
    d.resolution = 60;
    d.defaults.max_density = 5;
    d.defaults.size = 0.02f;
    d.defaults.alpha = 0.3f;
    d.defaults.fade_color = {0.85f, 0.8f, 0.72f};
    d.defaults.fade_alpha = 0;
    d.defaults.fade_size = 0.05f;
    d.defaults.lifetime = 1.0f;
    d.defaults.drag = 0.6f;
    d.dissolve.start = 2.5f;
    d.dissolve.wind = {3.0f, 1.2f, -0.6f};
    d.dissolve.front_speed = 0.5f;
    return s;
}

// One voxel (Figure 7): particles rise out of it, turn dark red and vanish, added up as light.
SceneDesc fire() {
    SceneDesc s = diffuse_base("fire");
    s.max_particles = 4000;
    s.camera = {{0.0f, 0.45f, 1.4f}, {0.0f, 0.35f, 0.0f}, 40.0f};
    DiffuseDesc& d = s.diffuse;
    d.mesh = "box";
    d.scale = 0.18f;
    d.resolution = 1;
    d.additive = true;
    d.defaults.max_density = 200;
    d.defaults.fill_time = 0.25f;
    d.defaults.color = {1.0f, 0.5f, 0.1f};
    d.defaults.alpha = 0.22f;
    d.defaults.size = 0.08f;
    d.defaults.fade_color = {0.55f, 0.08f, 0.02f};
    d.defaults.fade_alpha = 0;
    d.defaults.fade_size = 0.03f;
    d.defaults.lifetime = 0.7f;
    d.defaults.interpolation_time = 0.05f;
    d.defaults.drag = 1.5f;
    d.defaults.jitter = 0.35f;
    d.defaults.force = "linear";
    d.defaults.force_vector = {0, 5, 0};
    s.gravity = {0, 1.5f, 0};  // buoyancy outside the voxel
    return s;
}

// The fluffy bunny of the paper's Figure 8: the mesh's own colours, still.
SceneDesc bunny() {
    SceneDesc s = diffuse_base("bunny");
    s.max_particles = 120000;
    s.camera = {{0.1f, 0.5f, 1.7f}, {0.05f, 0.33f, 0.0f}, 40.0f};
    DiffuseDesc& d = s.diffuse;
    d.mesh = "bunny";
    d.scale = 1.4f;
    d.resolution = 60;
    d.defaults.max_density = 4;
    d.defaults.size = 0.018f;
    d.defaults.alpha = 0.3f;
    d.defaults.jitter = 0.25f;
    d.defaults.drag = 4;
    d.defaults.lifetime = 0.3f;
    return s;
}

}  // namespace

std::span<const std::string_view> diffuse_scene_names() {
    return kNames;
}

SceneDesc make_diffuse_scene(std::string_view name) {
    if (name == "ghost") return ghost();
    if (name == "dissolve") return dissolve();
    if (name == "fire") return fire();
    if (name == "bunny") return bunny();
    throw std::invalid_argument("unknown diffuse scene '" + std::string(name) + "'");
}

}  // namespace rivulet
