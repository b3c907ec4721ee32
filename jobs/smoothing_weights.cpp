#include "jobs/smoothing_weights.h"

#include <algorithm>
#include <cmath>

#include "jobs/cell_hash.h"
#include "jobs/sph_cubic_kernel.h"

namespace rivulet {
namespace {

constexpr float kSupportSpacings = 2.0f;
// Candidates one query may test (a pile of coincident particles would otherwise be quadratic).
constexpr std::uint32_t kMaxScan = 4096;

}  // namespace

double lattice_neighbour_count(double ratio) {
    const int reach = static_cast<int>(std::ceil(ratio));
    double n = 0;
    for (int k = -reach; k <= reach; ++k)
        for (int j = -reach; j <= reach; ++j)
            for (int i = -reach; i <= reach; ++i) {
                const double q = double(i * i + j * j + k * k) / (ratio * ratio);
                if (q < 1) n += 1 - q;
            }
    return n;
}

void smoothing_weights(ConstPositions p, float spacing, std::span<const float> vertices6,
                       std::vector<float>& weights) {
    const std::size_t n = p.size(), vertices = vertices6.size() / 6;
    weights.assign(vertices, 0.0f);
    if (n == 0 || vertices == 0) return;
    const float support = kSupportSpacings * spacing, r2_max = support * support;
    float origin[3] = {p.x[0], p.y[0], p.z[0]};
    for (std::size_t i = 1; i < n; ++i)
        origin[0] = std::min(origin[0], p.x[i]), origin[1] = std::min(origin[1], p.y[i]),
        origin[2] = std::min(origin[2], p.z[i]);
    std::vector<std::uint32_t> heads(cell_hash_table_size(n) + 1), order(n);
    std::vector<float> sx(n), sy(n), sz(n);
    CellHash hash = build_cell_hash(p, origin, support, heads, order);
    sort_cell_hash_positions(hash, p, sx, sy, sz);

    std::vector<float> count(n);
    for (std::size_t i = 0; i < n; ++i) {
        double c = 0;
        for_each_within(
            hash, p.x[i], p.y[i], p.z[i], r2_max, kMaxScan,
            [&](std::uint32_t, float, float, float, float r2) { c += 1.0 - double(r2 / r2_max); });
        count[i] = static_cast<float>(c);
    }
    const double full = lattice_neighbour_count(kSupportSpacings);
    const SphCubicKernel kernel(support);
    for (std::size_t v = 0; v < vertices; ++v) {
        const float* q = vertices6.data() + 6 * v;
        double num = 0, den = 0;
        for_each_within(hash, q[0], q[1], q[2], r2_max, kMaxScan,
                        [&](std::uint32_t j, float, float, float, float r2) {
                            const double w = kernel.w(r2);
                            num += w * count[j], den += w;
                        });
        const double x = den > 0 ? std::min(num / den / full, 1.0) : 0.0;
        weights[v] = static_cast<float>(x * x * x * (x * (6 * x - 15) + 10));
    }
}

}  // namespace rivulet
