#include "systems/io/ply_header.h"

#include <algorithm>
#include <array>
#include <cstring>
#include <span>

#include "systems/io/io_limits.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {

std::optional<std::size_t> PlyElement::find(std::string_view property) const {
    for (std::size_t i = 0; i < properties.size(); ++i) {
        if (properties[i].name == property) return i;
    }
    return std::nullopt;
}

const PlyProperty* PlyElement::first_list() const {
    for (const auto& p : properties) {
        if (p.is_list) return &p;
    }
    return nullptr;
}

std::size_t PlyElement::scalar_stride() const {
    std::size_t s = 0;
    for (const auto& p : properties) s += ply_scalar_size(p.type);
    return s;
}

std::uint64_t PlyElement::min_entry_bytes(PlyFormat format) const {
    if (format == PlyFormat::ascii) return 2 * properties.size();
    std::uint64_t s = 0;
    for (const auto& p : properties) s += ply_scalar_size(p.is_list ? p.count_type : p.type);
    return s;
}

std::optional<std::size_t> PlyHeader::find(std::string_view element) const {
    for (std::size_t i = 0; i < elements.size(); ++i) {
        if (elements[i].name == element) return i;
    }
    return std::nullopt;
}

namespace {

PlyFormat parse_format(const InputFile& in, std::span<const std::string_view> f) {
    if (f.size() != 3)
        in.fail_at_line(in.line_number(), "malformed format line (expected 'format <type> 1.0')");
    if (f[2] != "1.0" && f[2] != "1")
        in.fail_at_line(in.line_number(), "unsupported PLY version " + quoted(f[2]));
    if (f[1] == "ascii") return PlyFormat::ascii;
    if (f[1] == "binary_little_endian") return PlyFormat::binary_little_endian;
    if (f[1] == "binary_big_endian") return PlyFormat::binary_big_endian;
    in.fail_at_line(in.line_number(), "unknown PLY format " + quoted(f[1]));
}

PlyElement parse_element(const InputFile& in, std::span<const std::string_view> f) {
    if (f.size() != 3)
        in.fail_at_line(in.line_number(), "malformed element line (expected 'element <name> <count>')");
    const auto count = parse_uint64(f[2]);
    if (!count)
        in.fail_at_line(in.line_number(), "element count " + quoted(f[2]) + " is not a non-negative integer");
    if (*count > kMaxElementCount) {
        in.fail_at_line(in.line_number(), "element '" + std::string(f[1]) + "' declares " +
                                              std::to_string(*count) + " entries, more than the limit of " +
                                              std::to_string(kMaxElementCount));
    }
    return PlyElement{std::string(f[1]), *count, {}};
}

PlyScalar parse_type(const InputFile& in, std::string_view name) {
    const auto t = ply_scalar_from_name(name);
    if (!t) in.fail_at_line(in.line_number(), "unknown property type " + quoted(name));
    return *t;
}

PlyProperty parse_property(const InputFile& in, std::span<const std::string_view> f) {
    PlyProperty p;
    if (f.size() >= 2 && f[1] == "list") {
        if (f.size() != 5) {
            in.fail_at_line(in.line_number(),
                            "malformed list property (expected 'property list <count> <item> <name>')");
        }
        p.is_list = true;
        p.count_type = parse_type(in, f[2]);
        if (!ply_scalar_is_integer(p.count_type))
            in.fail_at_line(in.line_number(), "list count type must be an integer type");
        p.type = parse_type(in, f[3]);
        p.name = f[4];
        return p;
    }
    if (f.size() != 3)
        in.fail_at_line(in.line_number(), "malformed property line (expected 'property <type> <name>')");
    p.type = parse_type(in, f[1]);
    p.name = f[2];
    return p;
}

}  // namespace

PlyHeader read_ply_header(InputFile& in) {
    // The magic is checked on raw bytes so a binary file fails with "not a PLY file" rather than with a
    // complaint about an over-long first line.
    std::array<std::byte, 3> magic{};
    if (in.read(magic.data(), magic.size()) != magic.size() || std::memcmp(magic.data(), "ply", 3) != 0) {
        in.fail("not a PLY file (does not start with 'ply')");
    }
    std::string line;
    if (!in.read_line(line, kMaxHeaderLine) || !trim(line).empty())
        in.fail("not a PLY file (first line is not 'ply')");

    PlyHeader h;
    bool have_format = false;
    std::vector<std::string_view> f;
    for (;;) {
        if (!in.read_line(line, kMaxHeaderLine)) in.fail("truncated PLY header: no 'end_header' line");
        split_fields(line, f);
        if (f.empty() || f[0] == "comment" || f[0] == "obj_info") continue;
        if (f[0] == "end_header") break;
        if (f[0] == "format") {
            if (have_format) in.fail_at_line(in.line_number(), "second 'format' line");
            h.format = parse_format(in, f);
            have_format = true;
            continue;
        }
        if (!have_format) in.fail_at_line(in.line_number(), "expected 'format' line, got " + quoted(f[0]));
        if (f[0] == "element") {
            h.elements.push_back(parse_element(in, f));
        } else if (f[0] == "property") {
            if (h.elements.empty()) in.fail_at_line(in.line_number(), "property before any element");
            PlyProperty p = parse_property(in, f);
            if (h.elements.back().find(p.name))
                in.fail_at_line(in.line_number(), "duplicate property '" + p.name + "'");
            h.elements.back().properties.push_back(std::move(p));
        } else {
            in.fail_at_line(in.line_number(), "unexpected header keyword " + quoted(f[0]));
        }
    }
    if (!have_format) in.fail("PLY header has no 'format' line");
    for (const auto& e : h.elements) {
        if (e.properties.empty() && e.count > 0)
            in.fail("element '" + e.name + "' has entries but no properties");
    }
    return h;
}

}  // namespace rivulet::io
