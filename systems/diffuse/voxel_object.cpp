#include "systems/diffuse/voxel_object.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "systems/diffuse/procedural_meshes.h"
#include "systems/io/assimp_mesh.h"

#ifndef RIVULET_DATA_DIR
#define RIVULET_DATA_DIR "data"
#endif

namespace rivulet {
namespace {

// The built-in voxel: soft, half-transparent motes that fade where they stand (docs/diffuse.md).
VoxelAttributesDesc builtin_defaults() {
    VoxelAttributesDesc d;
    d.max_density = 8;
    d.fill_time = 0.5f;
    d.alpha = 0.35f;
    d.size = 0.035f;
    d.fade_alpha = 0;
    d.lifetime = 1.0f;
    d.interpolation_time = 0.3f;
    d.drag = 2.0f;
    d.jitter = 0.05f;
    d.force = "none";
    d.force_rate = 0;
    d.force_pull = 0;
    return d;
}

// `top` with the fields `under` sets where `top` leaves them unset (-1, as scene_to_json writes them).
// Any other negative value, or a colour only partly unset, is a mistake the layering would otherwise read
// as unset, giving another look than the one asked for without a word: an error naming `where`.key.
VoxelAttributesDesc layered(const VoxelAttributesDesc& top, const VoxelAttributesDesc& under,
                            const std::string& where) {
    VoxelAttributesDesc r = top;
    const auto pick = [&](const char* key, float& a, float b) {
        if (a < 0 && a != -1.0f)
            throw std::invalid_argument(where + "." + key + ": must not be negative (-1: the default)");
        if (a < 0) a = b;
    };
    pick("max_density", r.max_density, under.max_density), pick("fill_time", r.fill_time, under.fill_time);
    pick("alpha", r.alpha, under.alpha), pick("size", r.size, under.size);
    pick("fade_alpha", r.fade_alpha, under.fade_alpha), pick("fade_size", r.fade_size, under.fade_size);
    pick("lifetime", r.lifetime, under.lifetime);
    pick("interpolation_time", r.interpolation_time, under.interpolation_time);
    pick("drag", r.drag, under.drag), pick("jitter", r.jitter, under.jitter);
    pick("force_rate", r.force_rate, under.force_rate), pick("force_pull", r.force_pull, under.force_pull);
    const auto pick_colour = [&](const char* key, Vec3f& c, Vec3f b) {
        if (c.x < 0 || c.y < 0 || c.z < 0) {
            if (!(c.x == -1.0f && c.y == -1.0f && c.z == -1.0f))
                throw std::invalid_argument(
                    where + "." + key + ": colour components must be in [0, 1] ([-1, -1, -1]: the default)");
            c = b;
        }
    };
    pick_colour("color", r.color, under.color), pick_colour("fade_color", r.fade_color, under.fade_color);
    if (r.fade_size < 0 && r.size > 0) r.fade_size = 1.5f * r.size;  // motes swell as they fade
    if (r.force.empty()) {
        r.force = under.force;
        r.force_vector = under.force_vector;
        r.about_region = under.about_region;
    }
    return r;
}

DiffuseForce force_kind(const std::string& name, const std::string& where) {
    if (name == "none" || name.empty()) return DiffuseForce::kNone;
    if (name == "linear") return DiffuseForce::kLinear;
    if (name == "spiral") return DiffuseForce::kSpiral;
    if (name == "orbit") return DiffuseForce::kOrbit;
    if (name == "helix") return DiffuseForce::kHelix;
    throw std::invalid_argument(where + ".force: unknown force '" + name +
                                "': use none, linear, spiral, orbit or helix");
}

bool in_region(const DiffuseRegion& r, Vec3f p) {
    if (r.shape == "all") return true;
    if (r.shape == "sphere") return dot(p - r.center, p - r.center) <= r.radius * r.radius;
    return p.x >= r.min.x && p.y >= r.min.y && p.z >= r.min.z && p.x <= r.max.x && p.y <= r.max.y &&
           p.z <= r.max.z;
}

VoxelMaterial resolve(const VoxelAttributesDesc& a, Vec3f centre, float dt, const std::string& where) {
    validate_voxel_attributes(a, where);
    VoxelMaterial m;
    m.max_density = static_cast<std::uint16_t>(std::lround(a.max_density));
    const float per_frame = a.fill_time > 0 ? a.max_density * dt / a.fill_time : a.max_density;
    m.emit_per_frame = static_cast<std::uint16_t>(std::clamp(std::ceil(per_frame), 1.0f, 65535.0f));
    m.alpha = a.alpha;
    m.size = a.size;
    m.fade_color_set = a.fade_color.x >= 0;
    if (m.fade_color_set)
        m.fade_rgba = pack_rgba(a.fade_color.x, a.fade_color.y, a.fade_color.z, a.fade_alpha);
    m.fade_rgba = (m.fade_rgba & 0x00ffffffu) | (pack_rgba(0, 0, 0, a.fade_alpha) & 0xff000000u);
    m.fade_size = a.fade_size;
    m.lifetime = a.lifetime;
    m.interpolation_time = a.interpolation_time;
    m.drag = a.drag;
    m.jitter = a.jitter;
    m.color_set = a.color.x >= 0;
    if (m.color_set) m.rgba = pack_rgba(a.color.x, a.color.y, a.color.z, a.alpha);
    m.force.kind = static_cast<std::uint8_t>(force_kind(a.force, where));
    const bool rotation = m.force.kind == std::uint8_t(DiffuseForce::kSpiral) ||
                          m.force.kind == std::uint8_t(DiffuseForce::kHelix);
    m.force.vector = rotation ? normalize(a.force_vector) : a.force_vector;
    m.force.rate = a.force_rate;
    m.force.pull = a.force_pull;
    m.step = make_voxel_step(m.force, m.drag, dt);
    m.about_region = a.about_region;
    m.region_centre = centre;
    return m;
}

}  // namespace

std::uint32_t pack_rgba(float r, float g, float b, float a) {
    const auto q = [](float v) {
        return static_cast<std::uint32_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255));
    };
    return q(r) | q(g) << 8 | q(b) << 16 | q(a) << 24;
}

void validate_voxel_attributes(const VoxelAttributesDesc& a, const std::string& where) {
    const auto check = [&](bool ok, const char* field, const char* what) {
        if (!ok) throw std::invalid_argument(where + "." + field + ": " + what);
    };
    check(a.max_density >= 1 && a.max_density <= 4096, "max_density", "must be in [1, 4096]");
    check(a.fill_time >= 0 && a.fill_time <= 3600, "fill_time", "must be in [0, 3600] seconds");
    check(a.alpha >= 0 && a.alpha <= 1, "alpha", "must be in [0, 1]");
    check(a.fade_alpha >= 0 && a.fade_alpha <= 1, "fade_alpha", "must be in [0, 1]");
    check(a.size > 0 && a.size <= 100, "size", "must be in (0, 100]");
    check(a.fade_size >= 0 && a.fade_size <= 100, "fade_size", "must be in [0, 100]");
    check(a.lifetime > 0 && a.lifetime <= 3600, "lifetime", "must be in (0, 3600] seconds");
    check(a.interpolation_time >= 0 && a.interpolation_time <= 3600, "interpolation_time",
          "must be in [0, 3600] seconds");
    check(a.drag >= 0 && a.drag <= 1000, "drag", "must be in [0, 1000] per second");
    check(a.jitter >= 0 && a.jitter <= 1000, "jitter", "must be in [0, 1000] m/s");
    check(a.force_rate >= 0 && a.force_rate <= 1000, "force_rate", "must be in [0, 1000] rad/s");
    check(a.force_pull >= 0 && a.force_pull <= 1000, "force_pull", "must be in [0, 1000]");
    check(finite(a.force_vector) && std::abs(a.force_vector.x) <= 1e4f &&
              std::abs(a.force_vector.y) <= 1e4f && std::abs(a.force_vector.z) <= 1e4f,
          "force_vector", "must be finite, each component within 1e4");
    const auto colour = [](Vec3f c) {
        return c.x < 0 || (c.x <= 1 && c.y >= 0 && c.y <= 1 && c.z >= 0 && c.z <= 1);
    };
    check(colour(a.color), "color", "must be in [0, 1] per channel");
    check(colour(a.fade_color), "fade_color", "must be in [0, 1] per channel");
    const DiffuseForce kind = force_kind(a.force, where);
    if (kind == DiffuseForce::kSpiral || kind == DiffuseForce::kHelix)
        check(dot(a.force_vector, a.force_vector) > 0, "force_vector", "a rotation needs a non-zero axis");
    if (kind == DiffuseForce::kOrbit) check(a.force_rate > 0, "force_rate", "an orbit needs a rate > 0");
}

void validate_diffuse_desc(const DiffuseDesc& d, const std::string& where) {
    const auto check = [&](bool ok, const std::string& what) {
        if (!ok) throw std::invalid_argument(where + ".diffuse." + what);
    };
    check(!d.mesh.empty(), "mesh: names no mesh");
    check(d.resolution >= 1 && d.resolution <= 256, "resolution: must be in [1, 256]");
    check(std::isfinite(d.scale) && d.scale > 0 && d.scale <= 1e4f, "scale: must be in (0, 1e4]");
    check(finite(d.position), "position: must be finite");
    const VoxelAttributesDesc base = layered(d.defaults, builtin_defaults(), where + ".diffuse.defaults");
    validate_voxel_attributes(base, where + ".diffuse.defaults");
    check(d.regions.size() <= 1000, "regions: at most 1000");
    for (std::size_t i = 0; i < d.regions.size(); ++i) {
        const DiffuseRegion& r = d.regions[i];
        const std::string at = "regions[" + std::to_string(i) + "]";
        check(r.shape == "box" || r.shape == "sphere" || r.shape == "all",
              at + ".shape: expected \"box\", \"sphere\" or \"all\"");
        check(finite(r.min) && finite(r.max) && finite(r.center) && std::isfinite(r.radius) && r.radius >= 0,
              at + ": needs finite min, max, center and a radius >= 0");
        const std::string attributes = where + ".diffuse." + at + ".attributes";
        validate_voxel_attributes(layered(r.attributes, base, attributes), attributes);
    }
    check(std::isfinite(d.dissolve.start) && finite(d.dissolve.wind) &&
              std::isfinite(d.dissolve.front_speed) && d.dissolve.front_speed >= 0 &&
              d.dissolve.front_speed <= 1e4f,
          "dissolve: start, wind and front_speed must be finite, front_speed >= 0");
    check(d.dissolve.start < 0 || dot(d.dissolve.wind, d.dissolve.wind) > 0,
          "dissolve.wind: must not be zero");
    check(d.colliders.size() <= 8, "colliders: at most 8");
    for (std::size_t i = 0; i < d.colliders.size(); ++i) {
        const DiffuseCollider& c = d.colliders[i];
        const std::string at = "colliders[" + std::to_string(i) + "]";
        check(c.shape == "sphere" || c.shape == "box" || c.shape == "mesh",
              at + ".shape: expected \"sphere\", \"box\" or \"mesh\"");
        check(std::isfinite(c.radius) && c.radius > 0 && c.radius <= 1e4f,
              at + ".radius: must be in (0, 1e4]");
        const Vec3f h = c.half_extents;
        check(finite(h) && h.x > 0 && h.y > 0 && h.z > 0 && h.x <= 1e4f && h.y <= 1e4f && h.z <= 1e4f,
              at + ".half_extents: must be in (0, 1e4]");
        check(c.shape != "mesh" || !c.mesh.empty(), at + ".mesh: a mesh collider names its mesh file");
        check(finite(c.from) && finite(c.to), at + ": from and to must be finite");
        check(std::isfinite(c.period) && c.period >= 0 && c.period <= 1e6f,
              at + ".period: must be in [0, 1e6]");
    }
}

ColoredMesh load_diffuse_mesh(const std::string& name, float scale, Vec3f position) {
    ColoredMesh mesh;
    if (name == "ghost") {
        mesh = make_ghost_mesh();
    } else if (name == "box") {
        mesh = make_box_mesh({-0.5f, 0, -0.5f}, {0.5f, 1, 0.5f});
    } else if (name == "sphere") {
        mesh = make_uv_sphere({0, 0.5f, 0}, 0.5f, 64, 32);
    } else if (name == "torus") {
        mesh = make_torus({0, 0.25f, 0}, 0.5f, 0.2f, 96, 48);
    } else if (name == "bunny") {
        mesh = read_colored_mesh(std::string(RIVULET_DATA_DIR) + "/bunny.ply");
    } else {
        mesh = read_colored_mesh(name);
    }
    for (std::size_t i = 0; i < mesh.positions.size(); i += 3) {
        mesh.positions[i] = mesh.positions[i] * scale + position.x;
        mesh.positions[i + 1] = mesh.positions[i + 1] * scale + position.y;
        mesh.positions[i + 2] = mesh.positions[i + 2] * scale + position.z;
    }
    return mesh;
}

VoxelObject build_voxel_object(const DiffuseDesc& desc, const ColoredMesh& mesh, float dt) {
    const SolidVoxels solid = voxelize(mesh, desc.resolution, 2);
    VoxelObject obj;
    obj.shape = solid.shape;
    const std::size_t n = obj.shape.count();
    obj.material.assign(n, kNoMaterial);
    obj.rgba.assign(n, 0);
    const Vec3f grid_centre =
        obj.shape.origin +
        Vec3f{float(obj.shape.nx), float(obj.shape.ny), float(obj.shape.nz)} * (0.5f * obj.shape.cell);
    const VoxelAttributesDesc base = layered(desc.defaults, builtin_defaults(), "diffuse.defaults");
    obj.materials.push_back(resolve(base, grid_centre, dt, "diffuse.defaults"));
    for (std::size_t r = 0; r < desc.regions.size(); ++r) {
        const DiffuseRegion& region = desc.regions[r];
        const Vec3f centre = region.shape == "sphere" ? region.center
                             : region.shape == "all"  ? grid_centre
                                                      : (region.min + region.max) * 0.5f;
        const std::string attributes = "diffuse.regions[" + std::to_string(r) + "].attributes";
        obj.materials.push_back(
            resolve(layered(region.attributes, base, attributes), centre, dt, attributes));
    }
    for (int iz = 0; iz < obj.shape.nz; ++iz)
        for (int iy = 0; iy < obj.shape.ny; ++iy)
            for (int ix = 0; ix < obj.shape.nx; ++ix) {
                const std::size_t v = obj.shape.index(ix, iy, iz);
                if (!solid.inside[v]) continue;
                const Vec3f c = obj.shape.centre(ix, iy, iz);
                std::uint16_t m = 0;
                for (std::size_t r = desc.regions.size(); r-- > 0;)
                    if (in_region(desc.regions[r], c)) {
                        m = static_cast<std::uint16_t>(r + 1);
                        break;
                    }
                const VoxelMaterial& mat = obj.materials[m];
                obj.material[v] = m;
                obj.rgba[v] =
                    mat.color_set ? mat.rgba : pack_rgba(solid.r[v], solid.g[v], solid.b[v], mat.alpha);
                obj.inside.push_back(static_cast<std::uint32_t>(v));
            }
    if (obj.inside.empty())
        throw std::invalid_argument("diffuse.mesh '" + desc.mesh +
                                    "': no voxel lies inside the mesh at resolution " +
                                    std::to_string(desc.resolution));
    return obj;
}

}  // namespace rivulet
