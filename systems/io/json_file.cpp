#include "systems/io/json_file.h"

#include <fstream>
#include <sstream>

namespace rivulet::io {

JsonFile read_json_file(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {JsonFileStatus::kCannotOpen, {}};
    std::ostringstream text;
    text << in.rdbuf();
    nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
    if (doc.is_discarded()) return {JsonFileStatus::kInvalid, {}};
    return {JsonFileStatus::kOk, std::move(doc)};
}

}  // namespace rivulet::io
