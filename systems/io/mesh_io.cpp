#include "systems/io/mesh_io.h"

#include <cmath>

#include "systems/io/mesh_formats.h"
#include "systems/io/text_parse.h"

namespace rivulet {
namespace {

// Checked before any file is opened, so bad input never leaves a half-written file behind.
void validate_for_write(const std::string& path, std::span<const float> v6,
                        std::span<const std::uint32_t> idx) {
    const std::string prefix = path + ": cannot write mesh: ";
    if (v6.size() % 6 != 0) {
        throw FileFormatError(prefix + "vertex array length " + std::to_string(v6.size()) +
                              " is not a multiple of 6");
    }
    if (idx.size() % 3 != 0) {
        throw FileFormatError(prefix + "index array length " + std::to_string(idx.size()) +
                              " is not a multiple of 3");
    }
    const std::size_t nv = v6.size() / 6;
    for (std::size_t i = 0; i < idx.size(); ++i) {
        if (idx[i] >= nv) {
            throw FileFormatError(prefix + "triangle " + std::to_string(i / 3) + " references vertex " +
                                  std::to_string(idx[i]) + " but there are " + std::to_string(nv) +
                                  " vertices");
        }
    }
}

void validate_after_read(const std::string& path, const MeshData& m) {
    for (std::size_t i = 0; i < m.vertices6.size(); ++i) {
        if (!std::isfinite(m.vertices6[i])) {
            throw FileFormatError(path + ": non-finite " + (i % 6 < 3 ? "position" : "normal") +
                                  " at vertex " + std::to_string(i / 6));
        }
    }
}

}  // namespace

void write_mesh(const std::string& path, std::span<const float> vertices6,
                std::span<const std::uint32_t> indices) {
    const std::string ext = io::lower_extension(path);
    if (ext != ".obj" && ext != ".ply" && ext != ".vtk") {
        throw FileFormatError(path + ": unknown mesh file extension " + io::quoted(ext) +
                              " (expected .obj, .ply or .vtk)");
    }
    validate_for_write(path, vertices6, indices);
    if (ext == ".obj") {
        io::write_obj_mesh(path, vertices6, indices);
    } else if (ext == ".ply") {
        io::write_ply_mesh(path, vertices6, indices);
    } else {
        io::write_vtk_mesh(path, vertices6, indices);
    }
}

MeshData read_mesh(const std::string& path) {
    const std::string ext = io::lower_extension(path);
    MeshData m;
    if (ext == ".obj") {
        m = io::read_obj_mesh(path);
    } else if (ext == ".ply") {
        m = io::read_ply_mesh(path);
    } else {
        throw FileFormatError(path + ": unsupported mesh file extension for reading " + io::quoted(ext) +
                              " (expected .obj or .ply)");
    }
    validate_after_read(path, m);
    return m;
}

}  // namespace rivulet
