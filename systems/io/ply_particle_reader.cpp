#include <algorithm>
#include <bit>
#include <memory>
#include <vector>

#include "systems/io/byte_order.h"
#include "systems/io/line_fields.h"
#include "systems/io/particle_readers.h"
#include "systems/io/ply_header.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {
namespace {

struct CoordinateColumns {
    std::size_t index[3];
};

CoordinateColumns find_xyz(const InputFile& in, const PlyElement& vertex) {
    if (const PlyProperty* list = vertex.first_list()) {
        in.fail("list property '" + list->name + "' on the vertex element is not supported");
    }
    CoordinateColumns c{};
    const char* names[3] = {"x", "y", "z"};
    for (int a = 0; a < 3; ++a) {
        const auto i = vertex.find(names[a]);
        if (!i) in.fail(std::string("vertex element has no '") + names[a] + "' property");
        c.index[a] = *i;
    }
    return c;
}

// Elements before "vertex" are skipped when every property is scalar (their size is then known);
// list-bearing ones would need a full parse for data we do not use, so they are rejected.
void skip_element(InputFile& in, const PlyHeader& h, const PlyElement& e) {
    if (const PlyProperty* list = e.first_list()) {
        in.fail("element '" + e.name + "' precedes 'vertex' and has list property '" + list->name +
                "'; only scalar elements may come before 'vertex'");
    }
    if (e.count == 0) return;
    if (h.format == PlyFormat::ascii) {
        LineFields lines(in);
        for (std::uint64_t i = 0; i < e.count; ++i) {
            if (!lines.next()) in.fail("truncated data in element '" + e.name + "'");
        }
        return;
    }
    const std::uint64_t stride = e.scalar_stride();
    if (e.count > in.remaining() / stride) in.fail("truncated data in element '" + e.name + "'");
    in.skip(e.count * stride);
}

// The common all-float layout avoids the indirect decoder call per value, which would otherwise dominate
// the decode of large files.
template <bool BigEndian>
void decode_float_records(const std::byte* buf, std::size_t count, std::size_t stride,
                          const std::size_t* offset, ParticleCloud& cloud) {
    for (std::size_t i = 0; i < count; ++i) {
        const std::byte* rec = buf + i * stride;
        cloud.x.push_back(std::bit_cast<float>(load_uint<std::uint32_t, BigEndian>(rec + offset[0])));
        cloud.y.push_back(std::bit_cast<float>(load_uint<std::uint32_t, BigEndian>(rec + offset[1])));
        cloud.z.push_back(std::bit_cast<float>(load_uint<std::uint32_t, BigEndian>(rec + offset[2])));
    }
}

ParticleCloud read_binary(InputFile& in, const PlyHeader& h, const PlyElement& v,
                          const CoordinateColumns& c) {
    const std::uint64_t stride = v.scalar_stride();
    const std::uint64_t n = v.count;
    if (n > in.remaining() / stride) {
        in.fail("truncated binary vertex data: expected " + std::to_string(n * stride) + " bytes, got " +
                std::to_string(in.remaining()));
    }
    std::size_t offset[3];
    PlyDecoder decode[3];
    for (int a = 0; a < 3; ++a) {
        std::size_t off = 0;
        for (std::size_t p = 0; p < c.index[a]; ++p) off += ply_scalar_size(v.properties[p].type);
        offset[a] = off;
        decode[a] = ply_decoder(v.properties[c.index[a]].type, h.big_endian());
    }

    bool all_float = true;
    for (int a = 0; a < 3; ++a) all_float = all_float && v.properties[c.index[a]].type == PlyScalar::float32;

    ParticleCloud cloud;
    // reserve + push_back: zero-filling first would touch every page twice.
    cloud.x.reserve(n), cloud.y.reserve(n), cloud.z.reserve(n);
    // Bounded chunks: bulk reads without a second copy of a possibly multi-gigabyte block.
    const std::size_t chunk = std::max<std::size_t>(1, (std::size_t{4} << 20) / stride);
    const auto buf = std::make_unique_for_overwrite<std::byte[]>(std::min<std::uint64_t>(chunk, n) * stride);
    for (std::uint64_t first = 0; first < n;) {
        const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(chunk, n - first));
        const std::size_t want = count * stride;
        const std::size_t got = in.read(buf.get(), want);
        if (got != want) {
            in.fail("truncated binary vertex data: expected " + std::to_string(n * stride) + " bytes, got " +
                    std::to_string(first * stride + got));
        }
        if (all_float && h.big_endian()) {
            decode_float_records<true>(buf.get(), count, stride, offset, cloud);
        } else if (all_float) {
            decode_float_records<false>(buf.get(), count, stride, offset, cloud);
        } else {
            for (std::size_t i = 0; i < count; ++i) {
                const std::byte* rec = buf.get() + i * stride;
                cloud.x.push_back(narrow_coordinate(decode[0](rec + offset[0])));
                cloud.y.push_back(narrow_coordinate(decode[1](rec + offset[1])));
                cloud.z.push_back(narrow_coordinate(decode[2](rec + offset[2])));
            }
        }
        first += count;
    }
    return cloud;
}

ParticleCloud read_ascii(InputFile& in, const PlyElement& v, const CoordinateColumns& c) {
    in.require_text_size("ASCII PLY");
    const std::uint64_t n = v.count;
    const std::size_t columns = v.properties.size();
    // Each value takes at least one digit and one separator (the very last may lack its newline).
    if (n > 0 && n * v.min_entry_bytes(PlyFormat::ascii) - 1 > in.remaining()) {
        in.fail("truncated ascii vertex data: " + std::to_string(n) + " vertices need at least " +
                std::to_string(n * v.min_entry_bytes(PlyFormat::ascii) - 1) + " bytes, only " +
                std::to_string(in.remaining()) + " follow the header");
    }
    ParticleCloud cloud;
    cloud.x.reserve(n), cloud.y.reserve(n), cloud.z.reserve(n);
    LineFields lines(in);
    double values[3] = {};
    for (std::uint64_t i = 0; i < n; ++i) {
        if (!lines.next()) {
            in.fail("truncated ascii vertex data: expected " + std::to_string(n) + " vertices, got " +
                    std::to_string(i));
        }
        const auto f = lines.fields();
        if (f.size() != columns) {
            lines.fail("expected " + std::to_string(columns) + " values per vertex, got " +
                       std::to_string(f.size()));
        }
        for (std::size_t k = 0; k < columns; ++k) {
            const auto value = parse_double(f[k]);
            if (!value) lines.fail(quoted(f[k]) + " is not a number");
            for (int a = 0; a < 3; ++a) {
                if (c.index[a] == k) values[a] = *value;
            }
        }
        cloud.x.push_back(narrow_coordinate(values[0]));
        cloud.y.push_back(narrow_coordinate(values[1]));
        cloud.z.push_back(narrow_coordinate(values[2]));
    }
    return cloud;
}

}  // namespace

ParticleCloud read_ply_particles(const std::string& path) {
    InputFile in(path);
    const PlyHeader h = read_ply_header(in);
    const auto vi = h.find("vertex");
    if (!vi) in.fail("PLY file has no 'vertex' element");
    const PlyElement& v = h.elements[*vi];
    const CoordinateColumns c = find_xyz(in, v);
    for (std::size_t e = 0; e < *vi; ++e) skip_element(in, h, h.elements[e]);
    // Elements after "vertex" (faces, ...) are never read.
    return h.format == PlyFormat::ascii ? read_ascii(in, v, c) : read_binary(in, h, v, c);
}

}  // namespace rivulet::io
