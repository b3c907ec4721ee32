#pragma once
// Per-format mesh writers and readers behind write_mesh / read_mesh. Writers receive input that
// write_mesh has already validated (sizes, index range).
#include <cstdint>
#include <span>
#include <string>

#include "systems/io/mesh_io.h"

namespace rivulet::io {

void write_obj_mesh(const std::string& path, std::span<const float> vertices6,
                    std::span<const std::uint32_t> indices);
void write_ply_mesh(const std::string& path, std::span<const float> vertices6,
                    std::span<const std::uint32_t> indices);
void write_vtk_mesh(const std::string& path, std::span<const float> vertices6,
                    std::span<const std::uint32_t> indices);

MeshData read_obj_mesh(const std::string& path);
MeshData read_ply_mesh(const std::string& path);

}  // namespace rivulet::io
