#include "systems/scenes/scene_json.h"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <vector>

#include "systems/io/io_limits.h"
#include "systems/io/json_fields.h"
#include "systems/io/json_file.h"
#include "systems/scenes/scene_validation.h"

namespace rivulet {

using json_fields::fail;
using nlohmann::json;

// The fields of each scene struct, in file order (json_fields.h walks them).
template <class F>
void members(Emitter& e, F&& f) {
    f("position", e.position), f("direction", e.direction), f("speed", e.speed), f("spread", e.spread);
    f("nozzle_radius", e.nozzle_radius), f("rate", e.rate);
}
template <class F>
void members(SphereCollider& c, F&& f) {
    f("center", c.center), f("radius", c.radius);
}
template <class F>
void members(BoxCollider& b, F&& f) {
    f("min", b.min), f("max", b.max);
}
template <class F>
void members(PoolDesc& p, F&& f) {
    f("enabled", p.enabled), f("x0", p.x0), f("z0", p.z0), f("size_x", p.size_x), f("size_z", p.size_z);
    f("nx", p.nx), f("nz", p.nz), f("level", p.level), f("wave_speed", p.wave_speed);
    f("damping", p.damping), f("impulse_scale", p.impulse_scale), f("max_dip", p.max_dip);
    f("drain", p.drain);
}
template <class F>
void members(CameraDesc& c, F&& f) {
    f("eye", c.eye), f("target", c.target), f("fov_y_deg", c.fov_y_deg);
}
template <class F>
void members(ContainerMotion& m, F&& f) {
    f("amplitude", m.amplitude), f("frequency", m.frequency);
}
template <class F>
void members(SphFluidBox& b, F&& f) {
    f("min", b.min), f("max", b.max), f("velocity", b.velocity);
}
template <class F>
void members(SphFluidSphere& b, F&& f) {
    f("center", b.center), f("radius", b.radius), f("velocity", b.velocity);
}
// The tank; its motion is the scene's container_motion (per-frame inputs), not the desc's sinusoid.
template <class F>
void members(SphContainer& c, F&& f) {
    f("box", c.box);
}
// Gravity, dt and colliders are the scene's fields; the rest is the fluid's (docs/sph.md).
template <class F>
void members(SphDesc& d, F&& f) {
    f("solver", d.solver), f("spacing", d.spacing), f("support_ratio", d.support_ratio);
    f("rest_density", d.rest_density), f("max_density_error", d.max_density_error);
    f("max_divergence_error", d.max_divergence_error), f("max_iterations", d.max_iterations);
    f("chebyshev", d.chebyshev);
    f("sound_speed", d.sound_speed), f("gamma", d.gamma), f("viscosity", d.viscosity);
    f("artificial_viscosity", d.artificial_viscosity), f("surface_tension", d.surface_tension);
    f("tension", d.tension), f("tension_threshold", d.tension_threshold), f("container", d.container);
    f("wall_pressure", d.wall_pressure), f("fluid_boxes", d.fluid_boxes), f("fluid_spheres", d.fluid_spheres);
    f("cfl", d.cfl), f("max_substeps", d.max_substeps), f("bounds", d.bounds);
}

// Flat in files ("look": {"water_color", "absorption", "environment"}): three keys do not need two levels.
template <class F>
void members(SceneLook& l, F&& f) {
    f("water_color", l.water.color), f("absorption", l.water.absorption);
    f("environment", l.environment.faces);
}

template <class F>
void members(VoxelAttributesDesc& a, F&& f) {
    f("max_density", a.max_density), f("fill_time", a.fill_time), f("color", a.color), f("alpha", a.alpha);
    f("size", a.size), f("fade_color", a.fade_color), f("fade_alpha", a.fade_alpha);
    f("fade_size", a.fade_size), f("lifetime", a.lifetime), f("interpolation_time", a.interpolation_time);
    f("drag", a.drag), f("jitter", a.jitter), f("force", a.force), f("force_vector", a.force_vector);
    f("force_rate", a.force_rate), f("force_pull", a.force_pull), f("about_region", a.about_region);
}
template <class F>
void members(DiffuseRegion& r, F&& f) {
    f("shape", r.shape), f("min", r.min), f("max", r.max), f("center", r.center), f("radius", r.radius);
    f("attributes", r.attributes);
}
template <class F>
void members(DiffuseCollider& c, F&& f) {
    f("shape", c.shape), f("radius", c.radius), f("half_extents", c.half_extents), f("mesh", c.mesh);
    f("from", c.from), f("to", c.to), f("period", c.period);
}
template <class F>
void members(DissolveDesc& d, F&& f) {
    f("start", d.start), f("wind", d.wind), f("front_speed", d.front_speed);
}
template <class F>
void members(DiffuseDesc& d, F&& f) {
    f("mesh", d.mesh), f("scale", d.scale), f("position", d.position), f("resolution", d.resolution);
    f("defaults", d.defaults), f("regions", d.regions), f("colliders", d.colliders),
        f("dissolve", d.dissolve);
    f("additive", d.additive);
}

void read(const json& j, SphSolver& out, const std::string& where) {
    if (j == "dfsph") {
        out = SphSolver::kDfsph;
    } else if (j == "wcsph") {
        out = SphSolver::kWcsph;
    } else {
        fail(where, "expected \"dfsph\" or \"wcsph\"");
    }
}
json write(SphSolver s) {
    return s == SphSolver::kDfsph ? "dfsph" : "wcsph";
}

// The simulation kind by name.
void read(const json& j, SimulationKind& out, const std::string& where) {
    if (j == "streams") {
        out = SimulationKind::kStreams;
    } else if (j == "sph") {
        out = SimulationKind::kSph;
    } else if (j == "diffuse") {
        out = SimulationKind::kDiffuse;
    } else {
        fail(where, "expected \"streams\", \"sph\" or \"diffuse\"");
    }
}
json write(SimulationKind k) {
    return k == SimulationKind::kStreams ? "streams" : k == SimulationKind::kSph ? "sph" : "diffuse";
}

template <class F>
void members(SceneDesc& s, F&& f) {
    f("name", s.name), f("simulation", s.simulation), f("sph", s.sph);
    f("particle_radius", s.particle_radius), f("max_particles", s.max_particles);
    f("dt", s.dt), f("substeps", s.substeps), f("warmup_frames", s.warmup_frames), f("seed", s.seed);
    f("lifetime", s.lifetime), f("gravity", s.gravity), f("ground_y", s.ground_y);
    f("restitution", s.restitution), f("friction", s.friction), f("emitters", s.emitters);
    f("spheres", s.spheres), f("boxes", s.boxes), f("pool", s.pool), f("v_min", s.v_min), f("v_max", s.v_max);
    f("camera", s.camera), f("container_motion", s.container_motion), f("diffuse", s.diffuse);
    f("look", s.look);
}

SceneDesc scene_from_json(const json& doc, const std::string& origin) {
    if (!doc.is_object()) fail(origin, "a scene file holds one JSON object");
    SceneDesc scene;
    json fields = doc;
    if (const auto it = fields.find("base"); it != fields.end()) {
        if (!it->is_string()) fail(origin + ": base", "expected the name of a built-in scene");
        scene = make_builtin_scene(it->get<std::string>());
        fields.erase("base");
    }
    json_fields::read(fields, scene, origin);
    validate_scene(scene, origin);
    return scene;
}

json scene_to_json(const SceneDesc& scene) {
    return json_fields::write(scene);
}

namespace {

// Face images are named relative to the scene file, so a scene and its images move together. Checked
// here rather than in validate_scene: a recording made elsewhere still replays without the images.
void resolve_environment(SceneDesc& scene, const std::string& path) {
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    std::vector<std::string>& faces = scene.look.environment.faces;
    for (std::size_t i = 0; i < faces.size(); ++i) {
        const std::filesystem::path face(faces[i]);
        if (face.is_relative()) faces[i] = (dir / face).lexically_normal().string();
        std::ifstream probe(faces[i], std::ios::binary);
        if (!probe) {
            fail(path + ": look.environment[" + std::to_string(i) + "]",
                 "cannot open the face image '" + faces[i] + "': " + std::strerror(errno));
        }
    }
}

// A diffuse object's mesh files, like the face images, are named relative to the scene file; the
// built-in meshes go by name.
void resolve_meshes(SceneDesc& scene, const std::string& path) {
    const std::filesystem::path dir = std::filesystem::path(path).parent_path();
    const auto resolve = [&](std::string& file) {
        for (const char* builtin : {"ghost", "box", "sphere", "torus", "bunny"})
            if (file == builtin) return;
        if (std::filesystem::path(file).is_relative()) file = (dir / file).lexically_normal().string();
    };
    if (scene.simulation != SimulationKind::kDiffuse) return;
    resolve(scene.diffuse.mesh);
    for (DiffuseCollider& c : scene.diffuse.colliders)
        if (c.shape == "mesh") resolve(c.mesh);
}

}  // namespace

SceneDesc load_scene_file(const std::string& path) {
    SceneDesc scene = scene_from_json(io::read_json_file(path, io::kMaxSceneFileBytes, "scene files"), path);
    resolve_environment(scene, path);
    resolve_meshes(scene, path);
    return scene;
}

SceneDesc resolve_scene(const std::string& name_or_path) {
    const std::string ext = ".json";
    if (name_or_path.size() > ext.size() &&
        name_or_path.compare(name_or_path.size() - ext.size(), ext.size(), ext) == 0)
        return load_scene_file(name_or_path);
    return make_builtin_scene(name_or_path);
}

}  // namespace rivulet
