#pragma once
// Shared helpers for tests: geometry checks on indexed triangle meshes.
#include <cstdint>
#include <span>
#include <string>

namespace rivulet::test {

// Number of undirected edges not shared by exactly two triangles, after welding vertices closer than
// `weld` (0 = compare indices only).
std::size_t count_open_edges(std::span<const float> positions3, std::span<const std::uint32_t> indices,
                             float weld = 0.0f);

std::string temp_path(const std::string& name);

}  // namespace rivulet::test
