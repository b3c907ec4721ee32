#pragma once
// Shared helpers for tests: geometry checks on indexed triangle meshes.
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "jobs/particle_spans.h"
#include "systems/scenes/scene.h"

namespace rivulet::test {

// An empty scene whose camera looks along -z at (0, 0.5, 0) from 3 units away, 40 degrees high: the
// screen-space fluid tests draw their particles in front of it.
SceneDesc facing_scene();

// A closed axis-aligned box as a renderer mesh: 6 floats per vertex (position, outward normal), four
// vertices and two triangles per face.
struct BoxMesh {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
};
BoxMesh box_mesh(const float (&lo)[3], const float (&hi)[3]);

// Number of undirected edges not shared by exactly two triangles, after welding vertices closer than
// `weld` (0 = compare indices only).
std::size_t count_open_edges(std::span<const float> positions3, std::span<const std::uint32_t> indices,
                             float weld = 0.0f);
// The first three of every `stride` floats: positions out of interleaved vertices.
std::vector<float> strided_positions(std::span<const float> vertices, std::size_t stride);

// Particle positions as the tests build them, viewed as the jobs take them.
struct PointCloud {
    std::vector<float> x, y, z;
    void add(float a, float b, float c) { x.push_back(a), y.push_back(b), z.push_back(c); }
    ConstPositions pos() const { return {x, y, z}; }
    std::size_t size() const { return x.size(); }
};

std::string temp_path(const std::string& name);

// Runs the rivulet executable with `args` (shell words) and collects stdout and stderr together.
struct Result {
    int status = -1;
    std::string output;
};
// `environment`: assignments put before the command, e.g. "RIVULET_NO_AVX2=1".
Result run_cli(const std::string& args, const std::string& environment = "");

nlohmann::json read_json(const std::string& path);
void write_text(const std::string& path, const std::string& text);

}  // namespace rivulet::test
