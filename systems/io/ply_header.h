#pragma once
// PLY header model and parser shared by the particle and mesh readers.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "systems/io/input_file.h"
#include "systems/io/ply_scalar.h"

namespace rivulet::io {

enum class PlyFormat { ascii, binary_little_endian, binary_big_endian };

struct PlyProperty {
    std::string name;
    PlyScalar type = PlyScalar::float32;  // item type for lists
    bool is_list = false;
    PlyScalar count_type = PlyScalar::uint8;  // lists only
};

struct PlyElement {
    std::string name;
    std::uint64_t count = 0;
    std::vector<PlyProperty> properties;

    std::optional<std::size_t> find(std::string_view property) const;
    const PlyProperty* first_list() const;
    // Bytes per entry when every property is scalar.
    std::size_t scalar_stride() const;
    // Lower bound on one entry's size in the body (binary bytes, or ascii characters counting one
    // separator per value), used to reject counts the file cannot hold before allocating.
    std::uint64_t min_entry_bytes(PlyFormat format) const;
};

struct PlyHeader {
    PlyFormat format = PlyFormat::ascii;
    std::vector<PlyElement> elements;

    std::optional<std::size_t> find(std::string_view element) const;
    bool big_endian() const { return format == PlyFormat::binary_big_endian; }
};

// Reads and validates everything up to and including "end_header"; `in` is left at the first body byte.
PlyHeader read_ply_header(InputFile& in);

}  // namespace rivulet::io
