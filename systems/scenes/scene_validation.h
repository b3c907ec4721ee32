#pragma once
// Every check a scene must pass before anything is allocated or simulated, in one place, so built-in
// scenes, scene files, recordings and command-line overrides obey the same limits (scene_limits.h).
#include <string>

#include "systems/scenes/scene.h"

namespace rivulet {

// Throws std::invalid_argument "<origin>: <key>: <what> (got <value>)" naming the first bad field.
// `origin` defaults to "scene '<name>'". SPH scenes are also checked for their grid, their particle count
// against max_particles and their buffers' size, by counting (never walking) the lattice.
void validate_scene(const SceneDesc& scene, const std::string& origin = {});

}  // namespace rivulet
