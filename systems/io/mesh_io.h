#pragma once
// Triangle mesh files. Vertices are interleaved 6 floats each (position xyz, normal xyz); indices hold
// three vertex indices per triangle.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "systems/io/file_format_error.h"

namespace rivulet {

// By extension, case-insensitively: .obj (v / vn / f a//a b//b c//c, shortest round-trip floats),
// .ply (binary little endian, float x y z nx ny nz, face list uchar uint vertex_indices), .vtk (legacy
// POLYDATA, binary big endian, NORMALS in POINT_DATA). Throws FileFormatError on a size that is not a
// multiple of 6 / 3, an index out of range, or any I/O failure (a partial file is removed). An empty
// mesh is written as a valid empty file.
void write_mesh(const std::string& path, std::span<const float> vertices6,
                std::span<const std::uint32_t> indices);

struct MeshData {
    std::vector<float> vertices6;
    std::vector<std::uint32_t> indices;
    std::size_t vertex_count() const { return vertices6.size() / 6; }
    std::size_t triangle_count() const { return indices.size() / 3; }
};

// .obj and .ply (ascii or binary). Triangles only; indices are range-checked and coordinates must be
// finite. Normals missing from the file read as zero.
MeshData read_mesh(const std::string& path);

}  // namespace rivulet
