#pragma once
// Screen-space fluid settings as JSON, for recordings (strict, like scene files).
#include <nlohmann/json.hpp>
#include <string>

#include "systems/render/screen_fluid.h"

namespace rivulet {

nlohmann::json screen_fluid_settings_to_json(const ScreenFluidSettings& settings);
// Throws std::invalid_argument naming the key on unknown keys, wrong types or invalid settings.
ScreenFluidSettings screen_fluid_settings_from_json(const nlohmann::json& doc, const std::string& origin);

}  // namespace rivulet
