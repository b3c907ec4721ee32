#pragma once
// VolumeSettings as JSON (recordings): every member by name; unknown members and bad values are errors.
#include <nlohmann/json.hpp>
#include <string>

#include "systems/volume/volume_settings.h"

namespace rivulet {

nlohmann::json volume_settings_to_json(const VolumeSettings& settings);
// Throws std::invalid_argument naming `origin` and the member.
VolumeSettings volume_settings_from_json(const nlohmann::json& doc, const std::string& origin);

}  // namespace rivulet
