#include "systems/io/text_parse.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace rivulet::io {
namespace {

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

std::string_view strip_plus(std::string_view t) {
    if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
    return t;
}

}  // namespace

std::optional<double> parse_double(std::string_view token) {
    const std::string_view t = strip_plus(token);
    if (t.empty()) return std::nullopt;
    double v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (end != t.data() + t.size()) return std::nullopt;
    if (ec == std::errc::result_out_of_range) {
        // from_chars does not say whether it overflowed or underflowed; strtod does (±HUGE_VAL vs ~0),
        // and the caller then reports overflow as a non-finite coordinate.
        return std::strtod(std::string(t).c_str(), nullptr);
    }
    if (ec != std::errc()) return std::nullopt;
    return v;
}

std::optional<std::uint64_t> parse_uint64(std::string_view token) {
    const std::string_view t = strip_plus(token);
    std::uint64_t v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
    return v;
}

std::optional<std::int64_t> parse_int64(std::string_view token) {
    const std::string_view t = strip_plus(token);
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || ec != std::errc() || end != t.data() + t.size()) return std::nullopt;
    return v;
}

void split_fields(std::string_view line, std::vector<std::string_view>& out) {
    out.clear();
    std::size_t i = 0;
    const std::size_t n = line.size();
    while (i < n) {
        while (i < n && is_space(line[i])) ++i;
        const std::size_t start = i;
        while (i < n && !is_space(line[i])) ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return s;
}

std::string to_lower_ascii(std::string_view s) {
    std::string r(s);
    for (char& c : r) {
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    return r;
}

std::string lower_extension(const std::string& path) {
    return to_lower_ascii(std::filesystem::path(path).extension().string());
}

std::string quoted(std::string_view token) {
    constexpr std::size_t kMax = 40;
    std::string r = "'";
    for (char c : token.substr(0, kMax)) {
        const auto u = static_cast<unsigned char>(c);
        r += (u >= 0x20 && u < 0x7f) ? c : '?';
    }
    if (token.size() > kMax) r += "...";
    return r + "'";
}

std::string number_text(double v) {
    char text[32];
    // Whole numbers as integers: a limit and a count read better as 2000000000 than as 2e+09.
    std::snprintf(text, sizeof text, v == std::floor(v) && std::abs(v) < 1e15 ? "%.0f" : "%.9g", v);
    return text;
}

std::string bytes_text(std::uint64_t bytes) {
    constexpr const char* kUnits[] = {"bytes", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
    if (bytes < 1024) return std::to_string(bytes) + " bytes";
    double v = static_cast<double>(bytes);
    int unit = 0;
    while (v >= 1024.0 && unit < 6) v /= 1024.0, ++unit;
    char text[32];
    std::snprintf(text, sizeof text, v == std::floor(v) ? "%.0f %s" : "%.1f %s", v, kUnits[unit]);
    return text;
}

}  // namespace rivulet::io
