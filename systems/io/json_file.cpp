#include "systems/io/json_file.h"

#include <string>
#include <string_view>

#include "systems/io/file_format_error.h"
#include "systems/io/input_file.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {
namespace {

// Every JSON document Rivulet reads nests a handful of levels. nlohmann's parser is iterative, but
// dump() and comparisons recurse, so a document of a million '[' would overflow the stack later on.
constexpr int kMaxJsonDepth = 64;

// The deepest nesting of arrays and objects, brackets inside strings left out; stops past `limit`.
int nesting_depth(std::string_view text, int limit) {
    int depth = 0, deepest = 0;
    bool in_string = false, escaped = false;
    for (const char c : text) {
        if (in_string) {
            if (escaped) {
                escaped = false;
            } else if (c == '\\') {
                escaped = true;
            } else if (c == '"') {
                in_string = false;
            }
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > deepest && (deepest = depth) > limit) break;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return deepest;
}

}  // namespace

nlohmann::json read_json_file(const std::string& path, std::uint64_t max_bytes, const std::string& kind) {
    InputFile in(path);
    if (in.size() > max_bytes)
        in.fail(std::to_string(in.size()) + " bytes is over the " + bytes_text(max_bytes) + " limit for " +
                kind);
    std::string text(static_cast<std::size_t>(in.size()), '\0');
    text.resize(in.read(reinterpret_cast<std::byte*>(text.data()), text.size()));
    if (nesting_depth(text, kMaxJsonDepth) > kMaxJsonDepth)
        in.fail("JSON nested deeper than " + std::to_string(kMaxJsonDepth) + " levels");
    try {
        return nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
        in.fail("not valid JSON (" + std::string(e.what()) + ")");
    }
}

}  // namespace rivulet::io
