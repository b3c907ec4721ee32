#include "systems/sim/sph_scenes.h"

#include <algorithm>
#include <cmath>

namespace rivulet {

namespace {

// Numerical sound speed for a fluid of depth `height` falling freely: 10x the largest speed sqrt(2 g H),
// which keeps density variation near 1 % (Monaghan 1994).
float sound_speed_for(float height, float g) {
    return 10.0f * std::sqrt(2.0f * g * height);
}

// Spacing giving about `particles` lattice points in `volume`.
float spacing_for(double volume, std::size_t particles) {
    return static_cast<float>(std::cbrt(volume / double(std::max<std::size_t>(particles, 1))));
}

BoxCollider frame_bounds(const SphDesc& d) {
    const SphContainer& c = d.container;
    const Vec3f reach = c.axis * std::abs(c.amplitude);
    const Vec3f r{std::abs(reach.x), std::abs(reach.y), std::abs(reach.z)};
    return {c.box.min - r, c.box.max + r};
}

}  // namespace

SphDesc sph_desc_of(const SceneDesc& scene) {
    SphDesc desc = scene.sph;
    desc.name = scene.name;
    desc.gravity = scene.gravity;
    desc.dt = scene.dt;
    desc.spheres = scene.spheres;
    desc.boxes = scene.boxes;
    return desc;
}

SphDesc make_dambreak_slab(float a, int per_width, int layers) {
    SphDesc d;
    d.name = "dambreak_slab";
    d.spacing = a / static_cast<float>(per_width);
    const float width = d.spacing * static_cast<float>(layers);
    d.container.box = {{0, 0, 0}, {6.0f * a, 3.0f * a, width}};
    d.fluid_boxes.push_back({{0, 0, 0}, {a, 2.0f * a, width}, {}});
    d.sound_speed = sound_speed_for(2.0f * a, 9.81f);
    d.viscosity = 0.05f * a;  // scales with the resolution-independent Reynolds number of the column
    d.max_substeps = 200;
    d.bounds = frame_bounds(d);
    return d;
}

SphDesc make_dambreak(std::size_t particles) {
    // Column a = 0.25 m wide, 2a high, 0.3 m across; tank 4a long, 3a high (Martin & Moyce n^2 = 2).
    SphDesc d;
    d.name = "dambreak";
    const float a = 0.25f, depth = 0.3f;
    d.spacing = spacing_for(double(a) * 2.0 * a * depth, particles);
    d.container.box = {{0, 0, 0}, {4.0f * a, 3.0f * a, depth}};
    d.fluid_boxes.push_back({{0, 0, 0}, {a, 2.0f * a, depth}, {}});
    d.sound_speed = sound_speed_for(2.0f * a, 9.81f);
    d.viscosity = 0.05f * a;
    d.max_substeps = 256;
    d.bounds = frame_bounds(d);
    return d;
}

SphDesc make_dambreak_reference(std::size_t particles) {
    // A cube column a = 1 m on each side, `gap` off the floor and the left wall, centred across.
    SphDesc d;
    d.name = "dambreak_reference";
    const float a = 1.0f, gap = 0.05f, length = 4.0f, height = 3.0f, depth = 1.5f;
    const float z0 = 0.5f * (depth - a);
    d.spacing = spacing_for(double(a) * a * a, particles);
    d.container.box = {{0, 0, 0}, {length, height, depth}};
    d.fluid_boxes.push_back({{gap, gap, z0}, {gap + a, gap + a, z0 + a}, {}});
    d.sound_speed = sound_speed_for(a, 9.81f);
    d.viscosity = 0.05f * a;
    d.max_substeps = 256;
    d.bounds = frame_bounds(d);
    return d;
}

SphDesc make_drop(std::size_t particles) {
    // A pool 0.15 m deep in a 0.6 x 0.6 m tank; a ball of radius 0.1 m starting 0.25 m above it at
    // 1 m/s downwards. Surface tension on (it shapes the ball and the splash).
    SphDesc d;
    d.name = "drop";
    const float side = 0.6f, depth = 0.15f, r = 0.1f;
    const double volume = double(side) * side * depth + 4.0 / 3.0 * 3.14159265 * double(r) * r * r;
    d.spacing = spacing_for(volume, particles);
    d.container.box = {{0, 0, 0}, {side, 0.7f, side}};
    d.fluid_boxes.push_back({{0, 0, 0}, {side, depth, side}, {}});
    d.fluid_spheres.push_back({{0.5f * side, depth + 0.25f + r, 0.5f * side}, r, {0, -1.0f, 0}});
    d.sound_speed = sound_speed_for(depth + 0.35f, 9.81f);
    d.viscosity = 0.01f;
    d.surface_tension = true;
    d.max_substeps = 256;
    d.bounds = frame_bounds(d);
    return d;
}

SphDesc make_slosh(std::size_t particles) {
    // A pool 0.2 m deep in a 0.8 x 0.5 x 0.3 m tank moved along x: 4 cm amplitude at the first sloshing
    // mode, f = sqrt(g k tanh(k H)) / (2 pi), k = pi / L (about 0.87 Hz), so the wave builds up.
    SphDesc d;
    d.name = "slosh";
    const float length = 0.8f, height = 0.5f, width = 0.3f, depth = 0.2f;
    d.spacing = spacing_for(double(length) * depth * width, particles);
    d.container.box = {{0, 0, 0}, {length, height, width}};
    const float k = 3.14159265f / length;
    d.container.axis = {1, 0, 0};
    d.container.amplitude = 0.04f;
    d.container.frequency = std::sqrt(9.81f * k * std::tanh(k * depth)) / (2.0f * 3.14159265f);
    d.fluid_boxes.push_back({{0, 0, 0}, {length, depth, width}, {}});
    d.sound_speed = sound_speed_for(height, 9.81f);
    d.viscosity = 0.01f;
    d.max_substeps = 256;
    d.bounds = frame_bounds(d);
    return d;
}

}  // namespace rivulet
