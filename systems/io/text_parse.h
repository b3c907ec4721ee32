#pragma once
// Strict text helpers shared by the text formats: a number token must be a number and nothing else, so a
// stray letter is an error rather than a silently truncated value.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rivulet::io {

// Whole-token decimal or scientific number (also "nan"/"inf", which callers reject as non-finite with a
// better message than "not a number"). A leading '+' is accepted because some writers emit it.
std::optional<double> parse_double(std::string_view token);
std::optional<std::uint64_t> parse_uint64(std::string_view token);
std::optional<std::int64_t> parse_int64(std::string_view token);

// Splits on ASCII whitespace; views point into `line`.
void split_fields(std::string_view line, std::vector<std::string_view>& out);

std::string_view trim(std::string_view s);
std::string to_lower_ascii(std::string_view s);

// Lower-cased extension including the dot ("" if none), for case-insensitive format dispatch.
std::string lower_extension(const std::string& path);

// A number for an error message: whole numbers in full ("2000000000"), others to 9 significant digits
// ("1e-06", "0.25").
std::string number_text(double v);

// "512 bytes", "16 MiB", "2.5 GiB": a size for an error message.
std::string bytes_text(std::uint64_t bytes);

// Quotes a token for an error message, shortened so binary garbage cannot flood the message.
std::string quoted(std::string_view token);

}  // namespace rivulet::io
