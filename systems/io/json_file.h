#pragma once
// Reading a whole JSON document from a file (scene files, recordings, bench reports). Each caller words
// its own errors, so the outcome comes back as a status instead of an exception.
#include <string>

#include <nlohmann/json.hpp>

namespace rivulet::io {

enum class JsonFileStatus { kOk, kCannotOpen, kInvalid };

struct JsonFile {
    JsonFileStatus status = JsonFileStatus::kCannotOpen;
    nlohmann::json doc;  // the document when status is kOk
};

JsonFile read_json_file(const std::string& path);

}  // namespace rivulet::io
