#include <array>
#include <vector>

#include "systems/io/coordinate.h"
#include "systems/io/io_limits.h"
#include "systems/io/line_fields.h"
#include "systems/io/mesh_formats.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {
namespace {

struct FaceCorner {
    std::uint32_t vertex = 0;
    std::optional<std::uint32_t> normal;
};

// OBJ indices are 1-based; negative ones count back from the most recent element.
std::uint32_t resolve_index(const LineFields& lines, std::string_view token, std::size_t defined,
                            const char* what) {
    const auto i = parse_int64(token);
    if (!i) lines.fail(std::string(what) + " index " + quoted(token) + " is not an integer");
    const auto n = static_cast<std::int64_t>(defined);
    const std::int64_t zero_based = *i > 0 ? *i - 1 : n + *i;
    if (*i == 0 || zero_based < 0 || zero_based >= n) {
        lines.fail(std::string(what) + " index " + std::to_string(*i) + " out of range (" +
                   std::to_string(defined) + " defined so far)");
    }
    return static_cast<std::uint32_t>(zero_based);
}

// "v", "v/t", "v//n" or "v/t/n".
FaceCorner parse_corner(const LineFields& lines, std::string_view token, std::size_t nv, std::size_t nn) {
    FaceCorner c;
    const std::size_t s1 = token.find('/');
    c.vertex = resolve_index(lines, token.substr(0, s1), nv, "vertex");
    if (s1 == std::string_view::npos) return c;
    const std::size_t s2 = token.find('/', s1 + 1);
    if (s2 != std::string_view::npos && s2 + 1 < token.size()) {
        c.normal = resolve_index(lines, token.substr(s2 + 1), nn, "normal");
    }
    return c;
}

std::array<float, 3> parse_triple(const LineFields& lines, std::span<const std::string_view> f) {
    if (f.size() < 4)
        lines.fail("'" + std::string(f[0]) + "' needs 3 numbers, got " + std::to_string(f.size() - 1));
    std::array<float, 3> r{};
    for (std::size_t a = 0; a < 3; ++a) {
        const auto v = parse_double(f[a + 1]);
        if (!v) lines.fail(quoted(f[a + 1]) + " is not a number");
        r[a] = narrow_coordinate(*v);
    }
    return r;
}

}  // namespace

// Normals come from the face's normal references; without any, a file with exactly one "vn" per "v" is
// taken as per-vertex normals, otherwise they read as zero. Statements other than v / vn / f (groups,
// materials, texture coordinates, lines) are ignored.
MeshData read_obj_mesh(const std::string& path) {
    InputFile in(path);
    in.require_text_size("OBJ");
    LineFields lines(in);
    std::vector<std::array<float, 3>> positions, normals;
    std::vector<std::uint32_t> indices;
    std::vector<std::optional<std::uint32_t>> corner_normals;
    while (lines.next()) {
        const auto f = lines.fields();
        if (f[0] == "v") {
            if (positions.size() == kMaxElementCount)
                lines.fail("more than " + std::to_string(kMaxElementCount) + " vertices");
            positions.push_back(parse_triple(lines, f));
        } else if (f[0] == "vn") {
            normals.push_back(parse_triple(lines, f));
        } else if (f[0] == "f") {
            if (f.size() != 4) {
                lines.fail("face with " + std::to_string(f.size() - 1) +
                           " vertices; only triangles are supported");
            }
            for (std::size_t k = 1; k < 4; ++k) {
                const FaceCorner c = parse_corner(lines, f[k], positions.size(), normals.size());
                indices.push_back(c.vertex);
                corner_normals.push_back(c.normal);
            }
        }
    }

    MeshData m;
    m.vertices6.assign(positions.size() * 6, 0.0f);
    for (std::size_t i = 0; i < positions.size(); ++i) {
        for (std::size_t a = 0; a < 3; ++a) m.vertices6[6 * i + a] = positions[i][a];
    }
    bool any_face_normal = false;
    for (std::size_t k = 0; k < indices.size(); ++k) {
        if (!corner_normals[k]) continue;
        any_face_normal = true;
        for (std::size_t a = 0; a < 3; ++a)
            m.vertices6[6 * indices[k] + 3 + a] = normals[*corner_normals[k]][a];
    }
    if (!any_face_normal && normals.size() == positions.size()) {
        for (std::size_t i = 0; i < normals.size(); ++i) {
            for (std::size_t a = 0; a < 3; ++a) m.vertices6[6 * i + 3 + a] = normals[i][a];
        }
    }
    m.indices = std::move(indices);
    return m;
}

}  // namespace rivulet::io
