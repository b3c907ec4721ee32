#include <algorithm>
#include <memory>
#include <vector>

#include "systems/io/io_limits.h"
#include "systems/io/line_fields.h"
#include "systems/io/particle_readers.h"
#include "systems/io/ply_scalar.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {
namespace {

struct VtkPoints {
    bool binary = false;
    std::uint64_t count = 0;
    PlyScalar type = PlyScalar::float32;
};

std::string next_nonblank_line(InputFile& in, const char* expected) {
    std::string line;
    while (in.read_line(line, kMaxHeaderLine)) {
        if (!trim(line).empty()) return line;
    }
    in.fail(std::string("truncated VTK header: expected ") + expected);
}

// Header through the POINTS line; `in` is left at the first point value.
VtkPoints read_vtk_header(InputFile& in) {
    std::string line;
    if (!in.read_line(line, kMaxHeaderLine) ||
        !to_lower_ascii(trim(line)).starts_with("# vtk datafile version")) {
        in.fail("not a legacy VTK file (first line is not '# vtk DataFile Version x.x')");
    }
    if (!in.read_line(line, kMaxHeaderLine)) in.fail("truncated VTK header: no title line");

    VtkPoints pts;
    line = next_nonblank_line(in, "ASCII or BINARY");
    const std::string encoding = to_lower_ascii(trim(line));
    if (encoding == "binary") {
        pts.binary = true;
    } else if (encoding != "ascii") {
        in.fail_at_line(in.line_number(), "expected ASCII or BINARY, got " + quoted(trim(line)));
    }

    std::vector<std::string_view> f;
    line = next_nonblank_line(in, "DATASET");
    split_fields(line, f);
    if (f.size() != 2 || to_lower_ascii(f[0]) != "dataset") {
        in.fail_at_line(in.line_number(), "expected 'DATASET <type>', got " + quoted(trim(line)));
    }
    const std::string dataset = to_lower_ascii(f[1]);
    if (dataset != "polydata" && dataset != "unstructured_grid") {
        in.fail_at_line(in.line_number(),
                        "unsupported DATASET " + quoted(f[1]) + " (expected POLYDATA or UNSTRUCTURED_GRID)");
    }

    line = next_nonblank_line(in, "POINTS");
    split_fields(line, f);
    if (f.empty() || to_lower_ascii(f[0]) != "points") {
        in.fail_at_line(in.line_number(), "expected 'POINTS <n> float|double', got " + quoted(trim(line)));
    }
    if (f.size() != 3)
        in.fail_at_line(in.line_number(), "malformed POINTS line (expected 'POINTS <n> float|double')");
    const auto count = parse_uint64(f[1]);
    if (!count)
        in.fail_at_line(in.line_number(), "point count " + quoted(f[1]) + " is not a non-negative integer");
    if (*count > kMaxElementCount) {
        in.fail_at_line(in.line_number(), "POINTS declares " + std::to_string(*count) +
                                              " points, more than the limit of " +
                                              std::to_string(kMaxElementCount));
    }
    pts.count = *count;
    const std::string type = to_lower_ascii(f[2]);
    if (type == "double") {
        pts.type = PlyScalar::float64;
    } else if (type != "float") {
        in.fail_at_line(in.line_number(),
                        "unsupported POINTS data type " + quoted(f[2]) + " (expected float or double)");
    }
    return pts;
}

// Legacy VTK binary is big-endian by definition.
ParticleCloud read_binary(InputFile& in, const VtkPoints& pts) {
    const std::uint64_t stride = 3 * ply_scalar_size(pts.type);
    const std::uint64_t n = pts.count;
    if (n > in.remaining() / stride) {
        in.fail("truncated binary point data: expected " + std::to_string(n * stride) + " bytes, got " +
                std::to_string(in.remaining()));
    }
    const PlyDecoder decode = ply_decoder(pts.type, true);
    const std::size_t component = ply_scalar_size(pts.type);
    ParticleCloud cloud;
    // reserve + push_back: zero-filling first would touch every page twice.
    cloud.x.reserve(n), cloud.y.reserve(n), cloud.z.reserve(n);
    const std::size_t chunk = (std::size_t{4} << 20) / stride;
    const auto buf = std::make_unique_for_overwrite<std::byte[]>(std::min<std::uint64_t>(chunk, n) * stride);
    for (std::uint64_t first = 0; first < n;) {
        const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(chunk, n - first));
        const std::size_t got = in.read(buf.get(), count * stride);
        if (got != count * stride) {
            in.fail("truncated binary point data: expected " + std::to_string(n * stride) + " bytes, got " +
                    std::to_string(first * stride + got));
        }
        for (std::size_t i = 0; i < count; ++i) {
            const std::byte* rec = buf.get() + i * stride;
            cloud.x.push_back(narrow_coordinate(decode(rec)));
            cloud.y.push_back(narrow_coordinate(decode(rec + component)));
            cloud.z.push_back(narrow_coordinate(decode(rec + 2 * component)));
        }
        first += count;
    }
    return cloud;
}

// ASCII point values may wrap across lines in any grouping (VTK writers typically put 9 per line).
ParticleCloud read_ascii(InputFile& in, const VtkPoints& pts) {
    const std::uint64_t values = 3 * pts.count;
    if (values > 0 && 2 * values - 1 > in.remaining()) {
        in.fail("truncated ascii point data: " + std::to_string(pts.count) + " points need at least " +
                std::to_string(2 * values - 1) + " bytes, only " + std::to_string(in.remaining()) +
                " follow");
    }
    ParticleCloud cloud;
    cloud.x.reserve(pts.count), cloud.y.reserve(pts.count), cloud.z.reserve(pts.count);
    std::vector<float>* axis[3] = {&cloud.x, &cloud.y, &cloud.z};
    LineFields lines(in);
    std::uint64_t seen = 0;
    while (seen < values) {
        if (!lines.next()) {
            in.fail("truncated ascii point data: expected " + std::to_string(values) + " values, got " +
                    std::to_string(seen));
        }
        for (const std::string_view token : lines.fields()) {
            if (seen == values) break;  // whatever follows on this line belongs to the next section
            const auto v = parse_double(token);
            if (!v) lines.fail(quoted(token) + " is not a number");
            axis[seen % 3]->push_back(narrow_coordinate(*v));
            ++seen;
        }
    }
    return cloud;
}

}  // namespace

ParticleCloud read_vtk_particles(const std::string& path) {
    InputFile in(path);
    const VtkPoints pts = read_vtk_header(in);
    if (!pts.binary) in.require_text_size("ASCII VTK");
    return pts.binary ? read_binary(in, pts) : read_ascii(in, pts);
}

}  // namespace rivulet::io
