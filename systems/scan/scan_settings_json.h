#pragma once
// Scan conversion settings as JSON, for recordings and benchmark reports (strict, like scene files).
#include <nlohmann/json.hpp>
#include <string>

#include "systems/scan/scan_settings.h"

namespace rivulet {

nlohmann::json scan_settings_to_json(const ScanSettings& settings);
// Throws std::invalid_argument naming the key on unknown keys, wrong types or invalid settings.
ScanSettings scan_settings_from_json(const nlohmann::json& doc, const std::string& origin);

}  // namespace rivulet
