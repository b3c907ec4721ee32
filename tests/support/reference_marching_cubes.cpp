#include "support/reference_marching_cubes.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "jobs/marching_tables.h"
#include "systems/slices/slices_settings.h"

namespace rivulet::test {

namespace {

// F at every corner of the grid: term(q, px, py, pz) of every particle q, summed in the global order
// (slab of the centre, then particle index). A particle adds exactly +0 beyond its reach; skipping those
// farther than `reach` voxels in z (plus a slab for rounding) keeps the oracle quick without relying on
// the extractor's own reach.
template <class Term>
std::vector<float> corner_field(const SliceGrid& g, ConstPositions p, float reach, Term&& term) {
    const std::uint32_t nx = g.corners_x(), ny = g.corners_y(), nz = g.corners_z();
    std::vector<std::uint32_t> order(p.size());
    std::iota(order.begin(), order.end(), 0u);
    std::vector<std::int32_t> mid(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) mid[i] = SliceGrid::cell(p.z[i], g.oz, g.inv_voxel);
    std::stable_sort(order.begin(), order.end(), [&](auto a, auto b) { return mid[a] < mid[b]; });
    const std::int32_t skip = 2 * static_cast<std::int32_t>(std::ceil(reach / g.voxel)) + 2;
    std::vector<float> field(std::size_t(nx) * ny * nz);
    for (std::uint32_t k = 0; k < nz; ++k) {
        // The particles within `skip` slabs of k are one run of `order` (sorted by slab).
        const auto near = [&](std::uint32_t q) { return mid[q] >= std::int32_t(k) - skip; };
        const auto first = std::partition_point(order.begin(), order.end(), [&](auto q) { return !near(q); });
        const auto last = std::partition_point(first, order.end(),
                                               [&](auto q) { return mid[q] <= std::int32_t(k) + skip; });
        for (std::uint32_t j = 0; j < ny; ++j)
            for (std::uint32_t i = 0; i < nx; ++i) {
                const float px = g.cx(std::int32_t(i)), py = g.cy(std::int32_t(j)),
                            pz = g.cz(std::int32_t(k));
                float sum = 0.0f;
                for (auto q = first; q != last; ++q) sum += term(*q, px, py, pz);
                field[(std::size_t(k) * ny + j) * nx + i] = sum;
            }
    }
    return field;
}

ReferenceMesh polygonise(const SliceGrid& g, float iso, const std::vector<float>& field);

}  // namespace

ReferenceMesh reference_marching_cubes(const SliceGrid& g, float iso, ConstPositions p) {
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    return polygonise(g, iso, corner_field(g, p, g.rc, [&](std::uint32_t q, float px, float py, float pz) {
                          const float dx = p.x[q] - px, dy = p.y[q] - py, dz = p.z[q] - pz;
                          return f(dx * dx + dy * dy + dz * dz);
                      }));
}

ReferenceMesh reference_marching_cubes(const SliceGrid& g, float iso, ConstPositions p,
                                       const ConstKernelShapes& k) {
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    // The anisotropic term as jobs/anisotropic_kernels.h writes it, by the same float expressions as the
    // lookup cache (so the same bits).
    return polygonise(
        g, iso, corner_field(g, p, g.rc * kMaxAnisotropy, [&](std::uint32_t q, float px, float py, float pz) {
            const float dx = px - p.x[q], dy = py - p.y[q];
            const float a = (k.sxx[q] * dx + 2.0f * k.sxy[q] * dy) * dx + k.syy[q] * (dy * dy);
            const float dz = (p.z[q] + k.gx[q] * dx + k.gy[q] * dy) - pz;
            return k.amp[q] * f(a + k.c[q] * (dz * dz));
        }));
}

namespace {

ReferenceMesh polygonise(const SliceGrid& g, float iso, const std::vector<float>& field) {
    const std::uint32_t nx = g.corners_x(), ny = g.corners_y(), nz = g.corners_z();
    auto at = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
        return field[(std::size_t(k) * ny + j) * nx + i];
    };

    const MarchingTables& mt = marching_tables();
    ReferenceMesh out;
    std::unordered_map<std::uint64_t, std::uint32_t> vertex_of;
    for (std::uint32_t k = 0; k + 1 < nz; ++k)
        for (std::uint32_t j = 0; j + 1 < ny; ++j)
            for (std::uint32_t i = 0; i + 1 < nx; ++i) {
                float v[8];
                unsigned mask = 0;
                for (unsigned c = 0; c < 8; ++c) {
                    v[c] = at(i + (c & 1u), j + ((c >> 1) & 1u), k + ((c >> 2) & 1u));
                    if (v[c] >= iso) mask |= 1u << c;
                }
                for (std::uint32_t t = 0; t < mt.triangle_count[mask] * 3u; ++t) {
                    const auto e = static_cast<std::uint32_t>(mt.triangles[mask][t]);
                    const std::uint32_t axis = mt.edge_axis[e], lc = mt.edge_corner[e][0],
                                        hc = mt.edge_corner[e][1];
                    const std::uint32_t gi = i + (lc & 1u), gj = j + ((lc >> 1) & 1u),
                                        gk = k + ((lc >> 2) & 1u);
                    const std::uint64_t key = edge_key(gi, gj, gk, axis);
                    auto [it, fresh] = vertex_of.emplace(key, std::uint32_t(out.positions.size() / 3));
                    if (fresh) {
                        float pos[3] = {g.cx(std::int32_t(gi)), g.cy(std::int32_t(gj)),
                                        g.cz(std::int32_t(gk))};
                        pos[axis] = edge_crossing(pos[axis], g.voxel, v[lc], v[hc], iso);
                        out.positions.insert(out.positions.end(), pos, pos + 3);
                    }
                    out.indices.push_back(it->second);
                }
            }
    return out;
}

}  // namespace

std::vector<std::array<float, 9>> canonical_triangles(const std::vector<float>& pos, std::size_t stride,
                                                      const std::vector<std::uint32_t>& idx) {
    std::vector<std::array<float, 9>> tris;
    for (std::size_t t = 0; t + 2 < idx.size(); t += 3) {
        std::array<std::array<float, 3>, 3> v;
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) v[c][a] = pos[idx[t + c] * stride + a];
        const int first = static_cast<int>(std::min_element(v.begin(), v.end()) - v.begin());
        std::array<float, 9> tri;
        for (int c = 0; c < 3; ++c)
            for (int a = 0; a < 3; ++a) tri[c * 3 + a] = v[(first + c) % 3][a];
        tris.push_back(tri);
    }
    std::sort(tris.begin(), tris.end());
    return tris;
}

}  // namespace rivulet::test
