#include "jobs/volume_marching_cubes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace rivulet {
namespace {

// The brick's samples with a one-sample halo on every face (indices -1 .. 9 per axis), so that central
// differences at any of its samples read one array. The halo's edges and corners are never read.
constexpr int kPad = static_cast<int>(kBrickEdge) + 2;
constexpr int pad_index(int i, int j, int k) {
    return ((k + 1) * kPad + (j + 1)) * kPad + (i + 1);
}
constexpr int kPadPlane = kPad * kPad;
constexpr int kPadStride[3] = {1, kPad, kPadPlane};
using PaddedSamples = std::array<float, kPadPlane * kPad>;

const float* brick_samples(const DensityVolumeView& v, std::uint32_t slot) {
    return v.atlas.data() + atlas_offset(slot, 0, 0, 0);
}
constexpr std::size_t kAtlasRow = kAtlasEdge, kAtlasPlane = std::size_t(kAtlasEdge) * kAtlasEdge;

void load_samples(const DensityVolumeView& v, std::uint32_t slot, const std::uint32_t brick[3],
                  PaddedSamples& p) {
    const float* own = brick_samples(v, slot);
    for (int k = 0; k < int(kBrickEdge); ++k)
        for (int j = 0; j < int(kBrickEdge); ++j)
            std::copy_n(own + std::size_t(k) * kAtlasPlane + std::size_t(j) * kAtlasRow, kBrickEdge,
                        p.data() + pad_index(0, j, k));
    // The halo beyond face (axis, side) is the neighbour's layer next to the shared face: its local sample
    // 1 beyond a max face, 7 before a min face. Read from the neighbour's own copy rather than through
    // DensityVolumeView::sample (which reads a shared sample from the lowest brick holding it): both copies
    // are equal, and one slot look-up per face beats one per sample.
    const std::uint32_t count[3] = {v.grid.bx, v.grid.by, v.grid.bz};
    for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;
        for (int side = 0; side < 2; ++side) {
            std::uint32_t n[3] = {brick[0], brick[1], brick[2]};
            const bool inside = side ? n[axis] + 1 < count[axis] : n[axis] > 0;
            n[axis] = side ? n[axis] + 1 : n[axis] - 1;
            const std::int32_t nslot = inside ? v.brick_slot[v.grid.brick_index(n[0], n[1], n[2])] : -1;
            const float* src = nslot >= 0 ? brick_samples(v, static_cast<std::uint32_t>(nslot)) : nullptr;
            const int from = side ? 1 : int(kBrickCells) - 1, to = side ? int(kBrickEdge) : -1;
            for (int b = 0; b < int(kBrickEdge); ++b)
                for (int a = 0; a < int(kBrickEdge); ++a) {
                    int s[3], d[3];
                    s[axis] = from, d[axis] = to;
                    s[u] = d[u] = a;
                    s[w] = d[w] = b;
                    p[pad_index(d[0], d[1], d[2])] =
                        src ? src[std::size_t(s[2]) * kAtlasPlane + std::size_t(s[1]) * kAtlasRow +
                                  std::size_t(s[0])]
                            : 0.0f;
                }
        }
    }
}

}  // namespace

BrickMeshStats march_brick(const DensityVolumeView& v, std::uint32_t slot, const BrickMeshOut& out) {
    if (out.vertices.size() < 6 * std::size_t(kBrickMaxVertices) ||
        out.vertex_edge.size() < kBrickMaxVertices || out.edge_vertex.size() < kBrickEdgeSlots ||
        out.triangles.size() < 3 * std::size_t(kBrickMaxTriangles))
        throw std::invalid_argument("march_brick: output spans smaller than a brick's capacity");
    if (slot >= v.stored() || slot >= v.slot_max.size() || slot >= v.slot_brick.size() || !(v.iso > 0))
        throw std::invalid_argument("march_brick: no such stored brick, or iso not positive");

    std::fill_n(out.edge_vertex.begin(), kBrickEdgeSlots, kNoVertex);
    BrickMeshStats stats;
    // Without a sample on each side of iso no edge of the brick crosses it.
    if (!(v.slot_max[slot] >= v.iso) || v.slot_min[slot] >= v.iso) return stats;

    const DensityGrid& g = v.grid;
    const std::uint32_t id = v.slot_brick[slot];
    const std::uint32_t brick[3] = {id % g.bx, (id / g.bx) % g.by, id / (g.bx * g.by)};
    const bool last[3] = {brick[0] + 1 == g.bx, brick[1] + 1 == g.by, brick[2] + 1 == g.bz};
    const float origin[3] = {g.ox, g.oy, g.oz};
    PaddedSamples p;
    load_samples(v, slot, brick, p);
    const float iso = v.iso;

    // One vertex per crossed edge, in two runs so that the owned ones come first (the assembly copies
    // them as one block and needs only the rest looked up).
    std::uint32_t n = 0;
    const auto emit_edges = [&](bool owned_run) {
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                    const std::uint32_t c[3] = {i, j, k};
                    // An edge leaving this sample along one axis lies in the max face of another axis
                    // exactly when the sample does: ownership is the sample's.
                    const bool foreign = (i == kBrickCells && !last[0]) || (j == kBrickCells && !last[1]) ||
                                         (k == kBrickCells && !last[2]);
                    if (foreign == owned_run) continue;
                    const int at = pad_index(int(i), int(j), int(k));
                    const float f0 = p[at];
                    const bool in0 = f0 >= iso;
                    for (std::uint32_t axis = 0; axis < 3; ++axis) {
                        if (c[axis] == kBrickCells) continue;  // leaves the brick
                        const int step = kPadStride[axis];
                        const float f1 = p[at + step];
                        if (in0 == (f1 >= iso)) continue;
                        const float t = (iso - f0) / (f1 - f0);
                        float* vert = out.vertices.data() + 6 * std::size_t(n);
                        float grad[3];
                        for (int a = 0; a < 3; ++a) {
                            const std::uint32_t gc = brick[a] * kBrickCells + c[a];
                            vert[a] = origin[a] + g.voxel * static_cast<float>(gc);
                            // Central differences at both ends, interpolated like the position; the common
                            // factor 1 / (2 voxel) drops out in the normalisation.
                            const int s = kPadStride[a];
                            const float g0 = p[at + s] - p[at - s], g1 = p[at + step + s] - p[at + step - s];
                            grad[a] = (1.0f - t) * g0 + t * g1;
                        }
                        vert[axis] += t * g.voxel;
                        const float len2 = grad[0] * grad[0] + grad[1] * grad[1] + grad[2] * grad[2];
                        if (len2 > 0 && std::isfinite(len2)) {
                            const float inv = -1.0f / std::sqrt(len2);  // out of the fluid: along -grad F
                            for (int a = 0; a < 3; ++a) vert[3 + a] = grad[a] * inv;
                        } else {
                            // A flat spot of F: the edge itself goes from the inside end to the outside.
                            for (int a = 0; a < 3; ++a) vert[3 + a] = 0.0f;
                            vert[3 + axis] = in0 ? 1.0f : -1.0f;
                        }
                        const std::uint32_t e = brick_edge_slot(i, j, k, axis);
                        out.edge_vertex[e] = static_cast<std::uint16_t>(n);
                        out.vertex_edge[n] = static_cast<std::uint16_t>(e);
                        ++n;
                    }
                }
    };
    emit_edges(true);
    stats.owned = n;
    emit_edges(false);
    stats.vertices = n;

    const MarchingTables& mt = marching_tables();
    std::uint32_t edge_offset[12];  // edge slot of cube edge e relative to the cube's low corner's slot
    int corner_offset[8];
    for (std::uint32_t e = 0; e < 12; ++e) {
        const std::uint32_t lo = mt.edge_corner[e][0];
        edge_offset[e] = brick_edge_slot(lo & 1u, (lo >> 1) & 1u, (lo >> 2) & 1u, mt.edge_axis[e]);
    }
    for (int c = 0; c < 8; ++c)
        corner_offset[c] = pad_index(c & 1, (c >> 1) & 1, (c >> 2) & 1) - pad_index(0, 0, 0);

    std::uint32_t tri = 0;
    for (std::uint32_t k = 0; k < kBrickCells; ++k)
        for (std::uint32_t j = 0; j < kBrickCells; ++j)
            for (std::uint32_t i = 0; i < kBrickCells; ++i) {
                const int at = pad_index(int(i), int(j), int(k));
                unsigned mask = 0;
                for (int c = 0; c < 8; ++c) mask |= unsigned(p[at + corner_offset[c]] >= iso) << c;
                if (mask == 0 || mask == 255) continue;
                const std::uint32_t base = brick_edge_slot(i, j, k, 0);
                const std::uint32_t corners = mt.triangle_count[mask] * 3u;
                std::uint16_t* dst = out.triangles.data() + 3 * std::size_t(tri);
                for (std::uint32_t q = 0; q < corners; ++q)
                    dst[q] = out.edge_vertex[base +
                                             edge_offset[static_cast<std::uint32_t>(mt.triangles[mask][q])]];
                tri += mt.triangle_count[mask];
            }
    stats.triangles = tri;
    return stats;
}

}  // namespace rivulet
