#include "systems/scenes/scene_validation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "systems/diffuse/voxel_object.h"
#include "systems/io/text_parse.h"
#include "systems/scenes/scene_limits.h"
#include "systems/sim/sph_scenes.h"
#include "systems/sim/sph_simulation.h"

namespace rivulet {
using io::number_text;

namespace {
// Per metre: 1000 turns a millimetre of water opaque, already past any water worth drawing.
constexpr float kMaxWaterAbsorption = 1000.0f;
}  // namespace

void validate_scene(const SceneDesc& s, const std::string& origin) {
    const std::string where = origin.empty() ? "scene '" + s.name + "'" : origin;
    const auto check = [&](bool ok, const std::string& what) {
        if (!ok) throw std::invalid_argument(where + ": " + what);
    };
    const auto got = [](double v) { return ", got " + number_text(v); };
    const auto vec3 = [](Vec3f v) {
        return ", got [" + number_text(v.x) + ", " + number_text(v.y) + ", " + number_text(v.z) + "]";
    };
    check(s.warmup_frames >= 0 && s.warmup_frames <= kMaxWarmupFrames,
          "warmup_frames must be in [0, " + std::to_string(kMaxWarmupFrames) + "]" + got(s.warmup_frames));
    check(s.max_particles >= 1 && s.max_particles <= kMaxSceneParticles,
          "max_particles must be in [1, " + std::to_string(kMaxSceneParticles) + "]" + got(s.max_particles));
    check(std::isfinite(s.dt) && s.dt > 0 && s.dt <= 1, "dt must be in (0, 1]" + got(s.dt));
    check(s.substeps >= 1 && s.substeps <= 64, "substeps must be in [1, 64]" + got(s.substeps));
    check(std::isfinite(s.particle_radius) && s.particle_radius > 0,
          "particle_radius must be positive" + got(s.particle_radius));
    check(std::isfinite(s.lifetime) && s.lifetime > 0, "lifetime must be positive" + got(s.lifetime));
    // 1000 g: far past any fluid worth drawing; at 1e9 m/s^2 the dam break's first step overflowed to NaN.
    constexpr float kMaxGravity = 1e4f;
    check(finite(s.gravity) && std::abs(s.gravity.x) <= kMaxGravity && std::abs(s.gravity.y) <= kMaxGravity &&
              std::abs(s.gravity.z) <= kMaxGravity && std::isfinite(s.ground_y),
          "gravity must be finite, each component within 1e4 m/s^2, and ground_y finite" + vec3(s.gravity));
    check(std::isfinite(s.restitution) && s.restitution >= 0 && s.restitution <= 1,
          "restitution must be in [0, 1]" + got(s.restitution));
    check(std::isfinite(s.friction) && s.friction >= 0 && s.friction <= 1,
          "friction must be in [0, 1]" + got(s.friction));
    check(std::isfinite(s.v_min) && std::isfinite(s.v_max) && s.v_min < s.v_max, "need finite v_min < v_max");
    check(finite(s.camera.eye) && finite(s.camera.target) && std::isfinite(s.camera.fov_y_deg) &&
              s.camera.fov_y_deg > 0 && s.camera.fov_y_deg < 180,
          "camera must be finite with fov_y_deg in (0, 180)");
    check(finite(s.container_motion.amplitude) && std::isfinite(s.container_motion.frequency),
          "container_motion must be finite");
    for (const Emitter& e : s.emitters) {
        check(finite(e.position) && finite(e.direction) && dot(e.direction, e.direction) > 0,
              "emitter needs a finite position and a non-zero direction");
        check(std::isfinite(e.speed) && std::isfinite(e.spread) && std::isfinite(e.nozzle_radius),
              "emitter values must be finite");
        check(e.spread >= 0 && e.spread <= std::numbers::pi_v<float> && e.nozzle_radius >= 0,
              "emitter spread must be in [0, pi] and nozzle_radius >= 0");
        check(std::isfinite(e.rate) && e.rate >= 0 && e.rate <= 1e9f,
              "emitter rate must be in [0, 1e9]" + got(e.rate));
    }
    for (const SphereCollider& c : s.spheres)
        check(finite(c.center) && std::isfinite(c.radius) && c.radius >= 0,
              "sphere collider needs a finite center and a radius >= 0");
    for (const BoxCollider& b : s.boxes)
        check(
            finite(b.min) && finite(b.max) && b.min.x <= b.max.x && b.min.y <= b.max.y && b.min.z <= b.max.z,
            "box collider needs finite min <= max");
    const std::string samples = "[2, " + std::to_string(kMaxPoolSamples) + "]";
    check(s.pool.nx >= 2 && s.pool.nx <= kMaxPoolSamples, "pool.nx must be in " + samples + got(s.pool.nx));
    check(s.pool.nz >= 2 && s.pool.nz <= kMaxPoolSamples, "pool.nz must be in " + samples + got(s.pool.nz));
    const auto within = [](Vec3f v, float lo, float hi) {
        return finite(v) && v.x >= lo && v.x <= hi && v.y >= lo && v.y <= hi && v.z >= lo && v.z <= hi;
    };
    check(within(s.look.water.color, 0, 1),
          "look.water_color must be in [0, 1] per channel" + vec3(s.look.water.color));
    check(within(s.look.water.absorption, 0, kMaxWaterAbsorption),
          "look.absorption must be in [0, " + number_text(kMaxWaterAbsorption) + "] per channel (1/m)" +
              vec3(s.look.water.absorption));
    const std::vector<std::string>& faces = s.look.environment.faces;
    check(faces.empty() || faces.size() == 6,
          "look.environment needs six face images (+x, -x, +y, -y, +z, -z) or none, got " +
              std::to_string(faces.size()));
    for (std::size_t i = 0; i < faces.size(); ++i)
        check(!faces[i].empty(), "look.environment[" + std::to_string(i) + "] is an empty path");
    if (s.simulation == SimulationKind::kDiffuse) validate_diffuse_desc(s.diffuse, where);
    if (s.simulation == SimulationKind::kSph) {
        const SphDesc sph = sph_desc_of(s);
        if (const std::string problem = sph_desc_problem(sph, s.max_particles); !problem.empty())
            check(false, problem);
        // The scripted shake's largest move over a frame, |A| min(2, 2 pi f dt), against the tank's limit.
        const ContainerMotion& m = s.container_motion;
        const double move =
            m.frequency > 0 ? double(length(m.amplitude)) *
                                  std::min(2.0, 2.0 * std::numbers::pi * double(m.frequency) * double(s.dt))
                            : 0.0;
        check(move / double(s.dt) <= sph_max_tank_speed(sph),
              "container_motion moves the tank at up to " + number_text(move / double(s.dt)) +
                  " m/s over a frame, more than max_substeps substeps a frame can follow (" +
                  number_text(sph_max_tank_speed(sph)) +
                  " m/s): lower its amplitude or frequency, or raise "
                  "sph.max_substeps");
    }
}

}  // namespace rivulet
