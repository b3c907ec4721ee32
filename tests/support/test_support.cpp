#include "support/test_support.h"

#include <sys/wait.h>
#include <unistd.h>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace rivulet::test {

std::vector<float> strided_positions(std::span<const float> vertices, std::size_t stride) {
    std::vector<float> p;
    p.reserve(vertices.size() / stride * 3);
    for (std::size_t v = 0; v + stride <= vertices.size(); v += stride)
        p.insert(p.end(), vertices.begin() + std::ptrdiff_t(v), vertices.begin() + std::ptrdiff_t(v + 3));
    return p;
}

std::size_t count_open_edges(std::span<const float> p, std::span<const std::uint32_t> idx, float weld) {
    const std::size_t nv = p.size() / 3;
    std::vector<std::uint32_t> canon(nv);
    if (weld > 0) {
        std::map<std::tuple<long, long, long>, std::uint32_t> cell_rep;
        for (std::uint32_t i = 0; i < nv; ++i) {
            const auto key = std::make_tuple(std::lround(p[3 * i] / weld), std::lround(p[3 * i + 1] / weld),
                                             std::lround(p[3 * i + 2] / weld));
            canon[i] = cell_rep.emplace(key, i).first->second;
        }
    } else {
        for (std::uint32_t i = 0; i < nv; ++i) canon[i] = i;
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        const std::uint32_t v[3] = {canon[idx[t]], canon[idx[t + 1]], canon[idx[t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[0] == v[2]) continue;  // degenerate after welding
        for (int e = 0; e < 3; ++e) {
            auto a = v[e], b = v[(e + 1) % 3];
            edges[{std::min(a, b), std::max(a, b)}]++;
        }
    }
    return static_cast<std::size_t>(
        std::count_if(edges.begin(), edges.end(), [](auto& kv) { return kv.second != 2; }));
}

namespace {
// The test process's own folder under the system's temporary directory, removed when the process ends
// (a test that crashes leaves it for a look); ctest runs every test as a process of its own, and each
// one used to leave its folder behind: thousands after a day of runs.
struct TempFolder {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("rivulet-test-" + std::to_string(::getpid()));
    ~TempFolder() {
        std::error_code ignored;
        std::filesystem::remove_all(path, ignored);
    }
};
}  // namespace

std::string temp_path(const std::string& name) {
    static const TempFolder folder;
    std::filesystem::create_directories(folder.path);
    return (folder.path / name).string();
}

Result run_cli(const std::string& args, const std::string& environment) {
    Result r;
    const std::string cmd = environment + " " + std::string(RIVULET_CLI) + " " + args + " 2>&1";
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buf{};
    while (std::fgets(buf.data(), buf.size(), pipe)) r.output += buf.data();
    const int raw = ::pclose(pipe);
    r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
    return r;
}

nlohmann::json read_json(const std::string& path) {
    std::ifstream f(path);
    return nlohmann::json::parse(f);
}

void write_text(const std::string& path, const std::string& text) {
    std::ofstream(path) << text;
}

SceneDesc facing_scene() {
    SceneDesc s;
    s.camera.eye = {0, 0.5f, 3};
    s.camera.target = {0, 0.5f, 0};
    s.camera.fov_y_deg = 40;
    return s;
}

BoxMesh box_mesh(const float (&lo)[3], const float (&hi)[3]) {
    BoxMesh m;
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            const auto first = static_cast<std::uint32_t>(m.vertices.size() / 6);
            for (int corner = 0; corner < 4; ++corner) {
                float p[3], n[3] = {0, 0, 0};
                p[axis] = side ? hi[axis] : lo[axis];
                p[u] = (corner == 1 || corner == 2) ? hi[u] : lo[u];
                p[v] = corner >= 2 ? hi[v] : lo[v];
                n[axis] = side ? 1.0f : -1.0f;
                m.vertices.insert(m.vertices.end(), {p[0], p[1], p[2], n[0], n[1], n[2]});
            }
            for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(first + i);
        }
    }
    return m;
}

}  // namespace rivulet::test
