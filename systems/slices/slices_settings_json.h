#pragma once
// Marching slices settings as JSON, for recordings and benchmark reports (strict, like scene files).
#include <nlohmann/json.hpp>
#include <string>

#include "systems/slices/slices_settings.h"

namespace rivulet {

nlohmann::json slices_settings_to_json(const SlicesSettings& settings);
// A document without "field" reads as the classic field (what it meant before the spacing field).
// Throws std::invalid_argument naming the key on unknown keys, wrong types or invalid settings.
SlicesSettings slices_settings_from_json(const nlohmann::json& doc, const std::string& origin);

}  // namespace rivulet
