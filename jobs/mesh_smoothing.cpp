#include "jobs/mesh_smoothing.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace rivulet {
namespace {

constexpr float kLambda = 0.5f, kMu = -0.53f;

std::uint32_t find_root(std::vector<std::uint32_t>& parent, std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
}

// Six times the signed volume each triangle adds (against the origin), and the triangle's doubled area
// vector, in double.
void triangle_terms(std::span<const float> v6, const std::uint32_t* t, double& volume6, double n[3]) {
    const float* a = &v6[6 * std::size_t(t[0])];
    const float* b = &v6[6 * std::size_t(t[1])];
    const float* c = &v6[6 * std::size_t(t[2])];
    const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
    const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
    n[0] = e1[1] * e2[2] - e1[2] * e2[1];
    n[1] = e1[2] * e2[0] - e1[0] * e2[2];
    n[2] = e1[0] * e2[1] - e1[1] * e2[0];
    volume6 = double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) +
              double(a[1]) * (double(b[2]) * c[0] - double(b[0]) * c[2]) +
              double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0]);
}

// Per component (of `component[v]`): signed volume and area.
void component_volumes(std::span<const float> v6, std::span<const std::uint32_t> indices,
                       const std::vector<std::uint32_t>& component, std::vector<double>& volume,
                       std::vector<double>& area) {
    std::fill(volume.begin(), volume.end(), 0.0), std::fill(area.begin(), area.end(), 0.0);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        double v6x = 0, n[3];
        triangle_terms(v6, &indices[t], v6x, n);
        const std::uint32_t c = component[indices[t]];
        volume[c] += v6x / 6.0;
        area[c] += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    }
}

void area_normals(std::span<float> v6, std::span<const std::uint32_t> indices) {
    const std::size_t n_vertices = v6.size() / 6;
    std::vector<double> acc(3 * n_vertices, 0.0);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3) {
        double unused = 0, n[3];
        triangle_terms(v6, &indices[t], unused, n);
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a)
                acc[3 * std::size_t(indices[t + std::size_t(c)]) + std::size_t(a)] += n[a];
    }
    for (std::size_t v = 0; v < n_vertices; ++v) {
        const double* n = &acc[3 * v];
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (!(len > 0)) continue;  // an isolated vertex keeps its normal
        for (int a = 0; a < 3; ++a) v6[6 * v + 3 + std::size_t(a)] = static_cast<float>(n[a] / len);
    }
}

}  // namespace

MeshAdjacency mesh_adjacency(std::span<const std::uint32_t> indices, std::size_t vertex_count) {
    MeshAdjacency adj;
    adj.offsets.assign(vertex_count + 1, 0);
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int c = 0; c < 3; ++c) adj.offsets[indices[t + std::size_t(c)] + 1] += 2;
    std::partial_sum(adj.offsets.begin(), adj.offsets.end(), adj.offsets.begin());
    std::vector<std::uint32_t> cursor(adj.offsets.begin(), adj.offsets.end() - 1);
    adj.neighbours.resize(adj.offsets.back());
    for (std::size_t t = 0; t + 2 < indices.size(); t += 3)
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t v = indices[t + std::size_t(c)];
            adj.neighbours[cursor[v]++] = indices[t + std::size_t((c + 1) % 3)];
            adj.neighbours[cursor[v]++] = indices[t + std::size_t((c + 2) % 3)];
        }
    // Each neighbour once, ascending: sort and compact every row in place.
    std::uint32_t write = 0;
    for (std::size_t v = 0; v < vertex_count; ++v) {
        const auto first = adj.neighbours.begin() + adj.offsets[v],
                   last = adj.neighbours.begin() + adj.offsets[v + 1];
        std::sort(first, last);
        const auto unique_end = std::unique(first, last);
        adj.offsets[v] = write;
        for (auto it = first; it != unique_end; ++it) adj.neighbours[write++] = *it;
    }
    adj.offsets[vertex_count] = write;
    adj.neighbours.resize(write);
    return adj;
}

void laplacian_step(std::span<const float> in, std::span<float> out, std::size_t stride,
                    const MeshAdjacency& adjacency, float factor, std::size_t begin, std::size_t end,
                    std::span<const float> weights) {
    for (std::size_t v = begin; v < end; ++v) {
        const float* p = &in[stride * v];
        float* q = &out[stride * v];
        std::copy(p, p + stride, q);
        const std::uint32_t first = adjacency.offsets[v], last = adjacency.offsets[v + 1];
        if (first == last) continue;
        float sum[3] = {0, 0, 0};
        for (std::uint32_t e = first; e < last; ++e) {
            const float* n = &in[stride * adjacency.neighbours[e]];
            sum[0] += n[0], sum[1] += n[1], sum[2] += n[2];
        }
        const float inv = 1.0f / static_cast<float>(last - first);
        const float f = weights.empty() ? factor : factor * weights[v];
        for (int a = 0; a < 3; ++a) q[a] = p[a] + f * (sum[a] * inv - p[a]);
    }
}

SmoothingReport smooth_mesh(std::span<float> vertices6, std::span<const std::uint32_t> indices,
                            int iterations, std::span<const float> weights) {
    SmoothingReport report;
    const std::size_t n = vertices6.size() / 6;
    if (n == 0 || indices.empty()) return report;
    const MeshAdjacency adj = mesh_adjacency(indices, n);

    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    for (std::size_t v = 0; v < n; ++v)
        for (std::uint32_t e = adj.offsets[v]; e < adj.offsets[v + 1]; ++e) {
            const std::uint32_t a = find_root(parent, std::uint32_t(v)),
                                b = find_root(parent, adj.neighbours[e]);
            if (a != b) parent[std::max(a, b)] = std::min(a, b);
        }
    std::vector<std::uint32_t> component(n);
    for (std::size_t v = 0; v < n; ++v) {
        const std::uint32_t root = find_root(parent, std::uint32_t(v));
        component[v] = root == v ? report.components++ : component[root];
    }
    std::vector<double> volume0(report.components), area(report.components), volume1(report.components);
    component_volumes(vertices6, indices, component, volume0, area);

    const std::vector<float> original(vertices6.begin(), vertices6.end());
    const std::vector<double> area0 = area;
    std::vector<float> scratch(vertices6.size());
    for (int it = 0; it < iterations; ++it) {
        laplacian_step(vertices6, scratch, 6, adj, kLambda, 0, n, weights);
        laplacian_step(scratch, vertices6, 6, adj, kMu, 0, n, weights);
    }
    area_normals(vertices6, indices);
    // Move each component along its normals by the distance that gives back its volume: dV = A d.
    // A component that smoothing collapsed (a droplet of a few triangles shrinks to a point, or turns
    // inside out) has no normals to restore it along: it keeps its unsmoothed vertices. The others move
    // at most a tenth of the square root of their area (a third of a sphere's radius); the real
    // corrections are far smaller.
    component_volumes(vertices6, indices, component, volume1, area);
    std::vector<std::uint8_t> collapsed(report.components, 0);
    for (std::uint32_t c = 0; c < report.components; ++c) {
        collapsed[c] = !(volume1[c] * volume0[c] > 0) || std::abs(volume1[c]) < 0.5 * std::abs(volume0[c]);
        report.kept += collapsed[c];
    }
    for (std::size_t v = 0; v < n; ++v) {
        const std::uint32_t c = component[v];
        if (collapsed[c]) {
            std::copy(&original[6 * v], &original[6 * v] + 3, &vertices6[6 * v]);
            continue;
        }
        if (!(area[c] > 0)) continue;
        const double limit = 0.1 * std::sqrt(area0[c]);
        const float d = static_cast<float>(std::clamp((volume0[c] - volume1[c]) / area[c], -limit, limit));
        for (int a = 0; a < 3; ++a)
            vertices6[6 * v + std::size_t(a)] += d * vertices6[6 * v + 3 + std::size_t(a)];
    }
    area_normals(vertices6, indices);
    component_volumes(vertices6, indices, component, volume1, area);
    for (std::uint32_t c = 0; c < report.components; ++c)
        report.volume_before += volume0[c], report.volume_after += volume1[c];
    return report;
}

}  // namespace rivulet
