#include "systems/io/sequence_pattern.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "systems/io/text_parse.h"

namespace rivulet {
namespace {

std::size_t placeholder_position(const std::string& pattern) {
    const std::size_t pos = pattern.find("{}");
    if (pos == std::string::npos)
        throw FileFormatError(pattern + ": not a sequence pattern (no '{}' placeholder)");
    if (pattern.find("{}", pos + 2) != std::string::npos) {
        throw FileFormatError(pattern + ": sequence pattern has more than one '{}' placeholder");
    }
    return pos;
}

bool all_digits(std::string_view s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

}  // namespace

bool is_sequence_pattern(const std::string& s) {
    return s.find("{}") != std::string::npos;
}

std::vector<SequenceFrame> expand_sequence(const std::string& pattern) {
    const std::size_t pos = placeholder_position(pattern);
    const std::size_t slash = pattern.rfind('/');
    if (slash != std::string::npos && slash > pos) {
        throw FileFormatError(pattern +
                              ": the '{}' placeholder must be in the file name, not in a directory");
    }
    // The directory is kept as spelled so returned paths look like the pattern the user typed.
    const std::string dir_text = slash == std::string::npos ? "" : pattern.substr(0, slash + 1);
    const std::string prefix = pattern.substr(dir_text.size(), pos - dir_text.size());
    const std::string suffix = pattern.substr(pos + 2);
    const std::filesystem::path dir =
        dir_text.empty() ? std::filesystem::path(".") : std::filesystem::path(dir_text);

    std::error_code ec;
    std::filesystem::directory_iterator it(dir, ec);
    if (ec)
        throw FileFormatError(pattern + ": cannot list directory '" + dir.string() + "': " + ec.message());

    std::vector<SequenceFrame> frames;
    for (const auto& entry : it) {
        const std::string name = entry.path().filename().string();
        if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) ||
            !name.ends_with(suffix))
            continue;
        const std::string_view digits =
            std::string_view(name).substr(prefix.size(), name.size() - prefix.size() - suffix.size());
        if (!all_digits(digits)) continue;
        std::error_code type_ec;
        if (!entry.is_regular_file(type_ec)) continue;
        const auto number = io::parse_int64(digits);
        if (!number) throw FileFormatError(dir_text + name + ": frame number is too large");
        frames.push_back({*number, dir_text + name, static_cast<int>(digits.size())});
    }
    if (frames.empty()) throw FileFormatError(pattern + ": no files match the sequence pattern");
    std::sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return a.number < b.number; });
    for (std::size_t i = 1; i < frames.size(); ++i) {
        if (frames[i].number == frames[i - 1].number) {
            throw FileFormatError(pattern + ": ambiguous frame number " + std::to_string(frames[i].number) +
                                  ": '" + frames[i - 1].path + "' and '" + frames[i].path + "'");
        }
    }
    return frames;
}

std::string sequence_output_path(const std::string& out_pattern, std::int64_t number, int pad_width) {
    const std::size_t pos = placeholder_position(out_pattern);
    // Magnitude as unsigned so INT64_MIN has no overflow.
    const std::uint64_t magnitude = number < 0 ? std::uint64_t{0} - static_cast<std::uint64_t>(number)
                                               : static_cast<std::uint64_t>(number);
    std::string digits = std::to_string(magnitude);
    if (pad_width > 0 && digits.size() < static_cast<std::size_t>(pad_width)) {
        digits.insert(0, static_cast<std::size_t>(pad_width) - digits.size(), '0');
    }
    if (number < 0) digits.insert(0, 1, '-');
    return out_pattern.substr(0, pos) + digits + out_pattern.substr(pos + 2);
}

}  // namespace rivulet
