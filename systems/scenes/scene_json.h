#pragma once
// Scene files (docs/scenes.md): a JSON object with the fields of SceneDesc, optionally on top of a
// built-in scene ("base": "fountain"). Reading is strict: an unknown key, a wrong type or a value out of
// range is an error naming the key, so a typo never silently falls back to a default.
#include <nlohmann/json.hpp>
#include <string>

#include "systems/scenes/scene.h"

namespace rivulet {

// Throws std::invalid_argument with "<origin>: <key path>: <what>" on any problem.
SceneDesc scene_from_json(const nlohmann::json& doc, const std::string& origin);
// Every field, so that scene_from_json(scene_to_json(s)) == s (recordings embed scenes this way).
nlohmann::json scene_to_json(const SceneDesc& scene);

// Reads a scene file; throws FileFormatError when it cannot be read, is over the size cap for scene
// files (io_limits.h) or is not JSON, and std::invalid_argument as scene_from_json does.
SceneDesc load_scene_file(const std::string& path);
// `name_or_path` ending in .json is a scene file; anything else names a built-in scene.
SceneDesc resolve_scene(const std::string& name_or_path);

}  // namespace rivulet
