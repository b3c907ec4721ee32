#pragma once
// Reading a whole JSON document from a file (scene files, recordings, traces, bench reports): a regular
// file only (a link to /dev/zero or a pipe never ends), no larger than the caller's cap, checked before
// a byte is buffered.
#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace rivulet::io {

// Throws FileFormatError "<path>: <reason>" when the file cannot be opened, is not a regular file, is
// empty or larger than `max_bytes` (the message names `kind` and the limit), or is not valid JSON (the
// message names the byte where parsing stopped).
nlohmann::json read_json_file(const std::string& path, std::uint64_t max_bytes, const std::string& kind);

}  // namespace rivulet::io
