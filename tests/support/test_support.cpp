#include "support/test_support.h"

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <tuple>
#include <utility>
#include <vector>

namespace rivulet::test {

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

std::string temp_path(const std::string& name) {
    const auto dir = std::filesystem::temp_directory_path() / ("rivulet-test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return (dir / name).string();
}

}  // namespace rivulet::test
