#pragma once
// The built-in diffuse-object scenes (docs/diffuse.md): ghost, dissolve, fire and bunny.
#include <span>
#include <string_view>

#include "systems/scenes/scene.h"

namespace rivulet {

std::span<const std::string_view> diffuse_scene_names();
// Throws std::invalid_argument when `name` is not one of them.
SceneDesc make_diffuse_scene(std::string_view name);

}  // namespace rivulet
