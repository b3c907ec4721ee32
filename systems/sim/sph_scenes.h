#pragma once
// Built-in SPH scenes (docs/sph.md): each fills an SphDesc whose spacing is chosen so the initial fluid
// holds about `particles` particles.
//   dambreak  a water column (width a, height 2a) collapsing along a tank (Martin & Moyce 1952, n^2 = 2)
//   drop      a ball of water falling into a pool
//   slosh     a pool in a tank moved sinusoidally along x
#include <cstddef>

#include "systems/scenes/scene.h"
#include "systems/sim/sph_desc.h"

namespace rivulet {

SphDesc make_dambreak(std::size_t particles = 25000);
// The dam break of SPlisHSPlasH's DamBreakModel scene, the reference of docs/sph.md's speed figures: a
// cube column 1 m high in a tank 4 m long, 3 m high and 1.5 m across (benchmarks only).
SphDesc make_dambreak_reference(std::size_t particles = 24389);
SphDesc make_drop(std::size_t particles = 25000);
SphDesc make_slosh(std::size_t particles = 25000);

// The quasi-2D dam break of the tests: column width a, height 2a, `layers` particle layers across the
// tank (z), a / spacing = `per_width` particles across the column; tank 6a long.
SphDesc make_dambreak_slab(float a, int per_width, int layers);

// The fluid an SPH scene simulates: its sph desc with the scene's own gravity, dt and colliders, which
// are the truth for what every simulation shares.
SphDesc sph_desc_of(const SceneDesc& scene);

}  // namespace rivulet
