#include "jobs/mesh_quality.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

namespace rivulet {
namespace {

double percentile(std::vector<double>& v, double q) {
    const auto at = v.begin() + std::ptrdiff_t(std::min(v.size() - 1, std::size_t(q * double(v.size()))));
    std::nth_element(v.begin(), at, v.end());
    return *at;
}

}  // namespace

MeshQuality mesh_quality(std::span<const float> vertices, std::size_t stride,
                         std::span<const std::uint32_t> indices) {
    MeshQuality q;
    q.triangles = indices.size() / 3;
    const std::size_t vertex_count = stride > 0 ? vertices.size() / stride : 0;
    std::vector<double> angles, ratios;
    angles.reserve(q.triangles), ratios.reserve(q.triangles);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        double p[3][3] = {};
        bool in_range = true;
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t v = indices[t + std::size_t(c)];
            in_range = in_range && v < vertex_count;
            for (int a = 0; a < 3 && in_range; ++a)
                p[c][a] = vertices[std::size_t(v) * stride + std::size_t(a)];
        }
        double len[3] = {0, 0, 0};  // edge c is opposite corner c; read only when in range
        for (int c = 0; c < 3 && in_range; ++c) {
            const double* a = p[(c + 1) % 3];
            const double* b = p[(c + 2) % 3];
            len[c] = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
        }
        // Heron in its stable form (edges sorted a >= b >= c).
        double e[3] = {len[0], len[1], len[2]};
        if (in_range) std::sort(e, e + 3, [](double x, double y) { return x > y; });
        const double area4 = in_range ? (e[0] + (e[1] + e[2])) * (e[2] - (e[0] - e[1])) *
                                            (e[2] + (e[0] - e[1])) * (e[0] + (e[1] - e[2]))
                                      : 0.0;
        if (!in_range || !(area4 > 1e-24 * e[0] * e[0] * e[0] * e[0])) {
            ++q.degenerate;
            continue;
        }
        const double area = 0.25 * std::sqrt(area4), perimeter = e[0] + e[1] + e[2];
        // The smallest angle faces the shortest edge: sin = 2 area / (b a), by the law of sines' form.
        const double smallest =
            std::asin(std::min(1.0, 2.0 * area / (e[0] * e[1]))) * 180.0 / std::numbers::pi;
        const double inradius = 2.0 * area / perimeter, circumradius = e[0] * e[1] * e[2] / (4.0 * area);
        angles.push_back(smallest);
        ratios.push_back(circumradius / (2.0 * inradius));
    }
    if (angles.empty()) return q;
    double angle_sum = 0;
    q.min_angle_deg = angles[0], q.max_ratio = ratios[0];
    for (std::size_t i = 0; i < angles.size(); ++i) {
        angle_sum += angles[i];
        q.min_angle_deg = std::min(q.min_angle_deg, angles[i]),
        q.max_ratio = std::max(q.max_ratio, ratios[i]);
    }
    q.mean_min_angle_deg = angle_sum / double(angles.size());
    q.median_ratio = percentile(ratios, 0.5);
    q.min_angle_p05 = percentile(angles, 0.05);
    q.ratio_p95 = percentile(ratios, 0.95);
    return q;
}

}  // namespace rivulet
