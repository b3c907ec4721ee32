// The stream scenes of Hoetzlein & Höllerer 2009 §3: a radial fountain (Figure 12), a faucet and a garden
// hose, each falling into a height-field pool. Rates are tuned so the live count (rate x flight time) matches
// the particle counts of the paper's Table 1.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "systems/diffuse/diffuse_scenes.h"
#include "systems/scenes/scene.h"
#include "systems/sim/sph_scenes.h"

namespace rivulet {

namespace {

constexpr std::array<std::string_view, 10> kNames = {"fountain", "faucet", "hose",     "dambreak", "drop",
                                                     "slosh",    "ghost",  "dissolve", "fire",     "bunny"};

constexpr float deg(float degrees) {
    return degrees * std::numbers::pi_v<float> / 180.0f;
}

// Twelve arcs from a 0.5 m column: 64 degrees at 3.5 m/s rise 0.5 m above the nozzle (about 1 m above
// the ground) and land about 1.15 m out, after 0.75 s in flight.
SceneDesc fountain() {
    SceneDesc s;
    s.name = "fountain";
    s.particle_radius = 0.022f;
    s.max_particles = 16000;
    s.substeps = 3;
    s.warmup_frames = 120;
    s.seed = 12;
    s.lifetime = 3.0f;
    constexpr int kArcs = 12;
    constexpr float kNozzleHeight = 0.53f;
    const float elevation = deg(64);
    for (int k = 0; k < kArcs; ++k) {
        // Offset by half a step so no arc points straight at the camera on +z.
        const float a = 2.0f * std::numbers::pi_v<float> * (static_cast<float>(k) + 0.5f) / kArcs;
        const float ca = std::cos(a), sa = std::sin(a);
        Emitter e;
        e.position = {0.06f * ca, kNozzleHeight, 0.06f * sa};
        e.direction = {ca * std::cos(elevation), std::sin(elevation), sa * std::cos(elevation)};
        e.speed = 3.5f;
        e.spread = 0.015f;
        e.nozzle_radius = 0.012f;
        e.rate = 900.0f;
        s.emitters.push_back(e);
    }
    s.boxes.push_back({{-0.05f, 0.0f, -0.05f}, {0.05f, 0.48f, 0.05f}});  // the nozzle column
    s.pool.enabled = true;
    s.pool.x0 = -1.6f, s.pool.z0 = -1.6f;
    s.pool.size_x = 3.2f, s.pool.size_z = 3.2f;
    s.pool.nx = 128, s.pool.nz = 128;
    s.pool.level = 0.1f;
    s.pool.wave_speed = 0.9f;
    s.pool.damping = 0.6f;
    s.pool.impulse_scale = 0.0006f;
    s.pool.max_dip = 0.03f;
    s.v_min = -0.05f, s.v_max = 1.35f;
    s.camera = {{0.0f, 2.1f, 4.3f}, {0.0f, 0.4f, 0.0f}, 40.0f};
    return s;
}

// A spout 1.72 m up pours sideways; the stream curves down past a ball it glances off and lands in a
// basin 0.5 s later.
SceneDesc faucet() {
    SceneDesc s;
    s.name = "faucet";
    s.particle_radius = 0.02f;
    s.max_particles = 12000;
    s.substeps = 3;
    s.warmup_frames = 100;
    s.seed = 7;
    s.lifetime = 3.0f;
    Emitter e;
    e.position = {0.03f, 1.72f, 0.0f};
    e.direction = {1.0f, -0.2f, 0.0f};
    e.speed = 1.2f;
    e.spread = 0.02f;
    e.nozzle_radius = 0.025f;
    e.rate = 9600.0f;
    s.emitters.push_back(e);
    s.boxes.push_back({{-0.45f, 1.68f, -0.04f}, {0.0f, 1.76f, 0.04f}});   // spout arm
    s.boxes.push_back({{-0.53f, 0.0f, -0.06f}, {-0.41f, 1.76f, 0.06f}});  // its upright
    s.spheres.push_back({{0.52f, 0.72f, 0.13f}, 0.12f});
    s.pool.enabled = true;
    s.pool.x0 = -0.5f, s.pool.z0 = -0.7f;
    s.pool.size_x = 1.6f, s.pool.size_z = 1.4f;
    s.pool.nx = 112, s.pool.nz = 98;
    s.pool.level = 0.2f;
    s.pool.wave_speed = 0.8f;
    s.pool.damping = 0.6f;
    s.pool.impulse_scale = 0.00015f;
    s.pool.max_dip = 0.03f;
    s.v_min = -0.05f, s.v_max = 1.95f;
    s.camera = {{0.9f, 1.4f, 3.2f}, {0.3f, 0.9f, 0.0f}, 40.0f};
    return s;
}

// A garden hose near the ground at 40 degrees and 6.5 m/s: the arc peaks about 1.2 m up and lands
// 4.5 m away in a pond after 0.9 s.
SceneDesc hose() {
    SceneDesc s;
    s.name = "hose";
    s.particle_radius = 0.02f;
    s.max_particles = 14000;
    s.substeps = 4;
    s.warmup_frames = 120;
    s.seed = 3;
    s.lifetime = 3.0f;
    Emitter e;
    e.position = {-2.5f, 0.3f, 0.0f};
    e.direction = {std::cos(deg(40)), std::sin(deg(40)), 0.0f};
    e.speed = 6.5f;
    e.spread = 0.012f;
    e.nozzle_radius = 0.015f;
    e.rate = 6700.0f;
    s.emitters.push_back(e);
    s.pool.enabled = true;
    s.pool.x0 = 0.7f, s.pool.z0 = -1.3f;
    s.pool.size_x = 2.6f, s.pool.size_z = 2.6f;
    s.pool.nx = 128, s.pool.nz = 128;
    s.pool.level = 0.1f;
    s.pool.wave_speed = 1.0f;
    s.pool.damping = 0.5f;
    s.pool.impulse_scale = 0.0002f;
    s.pool.max_dip = 0.03f;
    s.v_min = -0.05f, s.v_max = 1.6f;
    s.camera = {{0.5f, 1.8f, 6.4f}, {0.5f, 0.7f, 0.0f}, 36.0f};
    return s;
}

// An SPH scene (Inácio et al. 2010 §III) around a fluid desc of systems/sim/sph_scenes.h: the desc's own
// motion becomes the scene's container motion (scripted per-frame inputs, so recordings carry it), the
// particle radius is half the lattice spacing, and the camera looks at the tank from the front and above.
SceneDesc sph_scene(std::string name, SphDesc d) {
    SceneDesc s;
    s.name = std::move(name);
    s.simulation = SimulationKind::kSph;
    s.container_motion = {d.container.axis * d.container.amplitude, d.container.frequency};
    d.container.amplitude = 0;
    s.particle_radius = 0.5f * d.spacing;
    s.max_particles = static_cast<std::uint32_t>(sph_seed_count(d));
    s.dt = d.dt;
    s.gravity = d.gravity;
    s.spheres = d.spheres;
    s.boxes = d.boxes;
    s.warmup_frames = 0;  // the interesting part is the start: the collapse, the fall, the first wave
    s.lifetime = 1e6f;
    const BoxCollider& b = d.bounds;
    s.ground_y = b.min.y;
    s.v_min = b.min.y - s.particle_radius;
    s.v_max = b.max.y + s.particle_radius;
    // The tank fills most of the 40 degree field of view (its bounding sphere just about), seen from the
    // front, right and above.
    const Vec3f size = b.max - b.min;
    const Vec3f target = (b.min + b.max) * 0.5f;
    const float radius = 0.5f * length(size);
    const float distance = 1.0f * radius / std::sin(deg(20));
    s.camera = {target + normalize(Vec3f{0.35f, 0.6f, 1.0f}) * distance, target, 40.0f};
    s.sph = std::move(d);
    return s;
}

}  // namespace

std::span<const std::string_view> builtin_scene_names() {
    return kNames;
}

SceneDesc make_builtin_scene(std::string_view name) {
    if (name == "fountain") return fountain();
    if (name == "faucet") return faucet();
    if (name == "hose") return hose();
    if (name == "dambreak") return sph_scene("dambreak", make_dambreak());
    if (name == "drop") return sph_scene("drop", make_drop());
    if (name == "slosh") return sph_scene("slosh", make_slosh());
    for (std::string_view n : diffuse_scene_names())
        if (name == n) return make_diffuse_scene(name);
    std::string known;
    for (std::string_view n : kNames) known += (known.empty() ? "" : ", ") + std::string(n);
    throw std::invalid_argument("unknown scene '" + std::string(name) + "'; built-in scenes: " + known);
}

}  // namespace rivulet
