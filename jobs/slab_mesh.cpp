#include "jobs/slab_mesh.h"

#include "jobs/bit_rows.h"
#include "jobs/marching_tables.h"
#include "jobs/slice_field.h"

namespace rivulet {

template <int W>
bool create_slab_vertices(const SlabMesh& m, BlockSweepStats& st) {
    using Row = BitRow<W>;
    const std::uint32_t n = m.n, n1 = n + 1;
    auto row = [](const std::uint64_t* base, std::size_t r) { return load_row<W>(base + r * W); };
    // The vertex on the edge from corner (i, r, t) along `axis`, whose corners hold lo and hi.
    auto create = [&](std::uint32_t axis, std::uint32_t i, std::uint32_t r, std::uint32_t t, float lo,
                      float hi) {
        if (st.vertices == m.max_vertices) {
            st.overflow = true;
            return;
        }
        ++st.vertices;
        const bool owned = (i < n || m.last[0]) && (r < n || m.last[1]) && (t < n || m.last[2]);
        const std::uint32_t id = owned ? st.owned++ : m.max_vertices - 1 - st.foreign;
        m.edges[((std::size_t(t) * n1 + r) * n1 + i) * 3 + axis] = id;
        float p[3] = {m.plane_x[i], m.plane_y[r], m.plane_z[t]};
        p[axis] = edge_crossing(p[axis], m.voxel, lo, hi, m.iso);
        float* const at = m.out.positions.data() + std::size_t(id) * 4;
        at[0] = p[0], at[1] = p[1], at[2] = p[2], at[3] = 0.0f;
        const std::uint64_t key =
            edge_key(static_cast<std::uint32_t>(m.i0) + i, static_cast<std::uint32_t>(m.j0) + r,
                     static_cast<std::uint32_t>(m.k0) + t, axis);
        if (!owned) {
            m.out.foreign[st.foreign++] = {key, id};
            return;
        }
        // An owned vertex on a max plane (c == n) lies on the grid's outer face: no block shares it.
        if ((axis != 0 && i == 0) || (axis != 1 && r == 0) || (axis != 2 && t == 0))
            m.out.border[st.border++] = {key, id};
    };
    // Edges of corner row r in slice t along `axis` that have no vertex yet among `want`; marks them.
    auto claim_edges = [&](std::uint32_t t, std::uint32_t axis, std::uint32_t r, Row want) {
        std::uint64_t* const at = m.made + ((std::size_t(t) * 3 + axis) * n1 + r) * W;
        const Row was = load_row<W>(at), fresh = and_not(want, was);
        store_row<W>(at, was | fresh);
        return fresh;
    };
    // Row by row: x and y edges of the bottom and top slices, then z edges (edges shared with cubes
    // visited before keep their vertex).
    const std::uint32_t k = m.k;
    for (std::int32_t r = m.row_lo; r <= m.row_hi + 1; ++r) {
        const auto ur = static_cast<std::uint32_t>(r);
        Row cubes = r <= m.row_hi ? row(m.visit, ur) : Row{};  // cubes of rows r - 1 and r
        if (r > m.row_lo) cubes = cubes | row(m.visit, ur - 1);
        const Row own_row = r <= m.row_hi ? row(m.visit, ur) : Row{};  // y edges: cubes of row r
        for (std::uint32_t t = k; t <= k + 1; ++t) {
            const float* const v = t == k ? m.lower : m.upper;
            const std::uint64_t* const in_t = t == k ? m.inside_lower : m.inside_upper;
            const Row here = row(in_t, ur);
            const Row x_new = claim_edges(t, 0, ur, cubes & (here ^ shr1(here)));
            for_each_bit(x_new,
                         [&](std::uint32_t i) { create(0, i, ur, t, v[ur * n1 + i], v[ur * n1 + i + 1]); });
            if (ur < n) {
                const Row y_new =
                    claim_edges(t, 1, ur, (own_row | shl1(own_row)) & (here ^ row(in_t, ur + 1)));
                for_each_bit(y_new, [&](std::uint32_t i) {
                    create(1, i, ur, t, v[ur * n1 + i], v[(ur + 1) * n1 + i]);
                });
            }
        }
        const Row z_new = claim_edges(
            k, 2, ur, (cubes | shl1(cubes)) & (row(m.inside_lower, ur) ^ row(m.inside_upper, ur)));
        for_each_bit(
            z_new, [&](std::uint32_t i) { create(2, i, ur, k, m.lower[ur * n1 + i], m.upper[ur * n1 + i]); });
    }
    return !st.overflow;
}

template <int W>
bool write_slab_triangles(const SlabMesh& m, BlockSweepStats& st) {
    using Row = BitRow<W>;
    const MarchingTables& mt = marching_tables();
    const std::uint32_t n1 = m.n + 1;
    auto row = [](const std::uint64_t* base, std::size_t r) { return load_row<W>(base + r * W); };
    std::uint32_t* const tris = m.out.triangles.data();
    const std::uint32_t* const edge_offset = m.edge_offset;
    std::uint32_t triangles = st.triangles;
    for (std::int32_t j = m.row_lo; j <= m.row_hi; ++j) {
        const auto uj = static_cast<std::uint32_t>(j);
        const Row cubes = row(m.visit, uj);
        // The case of cube i is read off the corner rows j, j + 1 of the bottom and top slices.
        const Row a = row(m.inside_lower, uj), b = row(m.inside_lower, uj + 1), c = row(m.inside_upper, uj),
                  d = row(m.inside_upper, uj + 1);
        const std::uint32_t* const slots = m.edges + (std::size_t(m.k) * n1 + uj) * n1 * 3;
        st.cubes += popcount(cubes);
        bool room = true;
        for_each_bit(cubes, [&](std::uint32_t i) {
            const std::uint32_t mask =
                two_bits(a, i) | two_bits(b, i) << 2 | two_bits(c, i) << 4 | two_bits(d, i) << 6;
            const std::uint32_t ntri = mt.triangle_count[mask];
            if (triangles + ntri > m.max_triangles) {
                room = false;
                return;
            }
            const std::uint32_t* const cube_slots = slots + i * 3;
            const std::int8_t* const edge = mt.triangles[mask].data();
            std::uint32_t* const tri = tris + std::size_t(triangles) * 3;
            for (std::uint32_t q = 0; q < ntri * 3; ++q)
                tri[q] = cube_slots[edge_offset[std::uint32_t(edge[q])]];
            triangles += ntri;
        });
        if (!room) {
            st.overflow = true;
            return false;
        }
    }
    st.triangles = triangles;
    return true;
}

template bool create_slab_vertices<1>(const SlabMesh&, BlockSweepStats&);
template bool create_slab_vertices<2>(const SlabMesh&, BlockSweepStats&);
template bool create_slab_vertices<3>(const SlabMesh&, BlockSweepStats&);
template bool write_slab_triangles<1>(const SlabMesh&, BlockSweepStats&);
template bool write_slab_triangles<2>(const SlabMesh&, BlockSweepStats&);
template bool write_slab_triangles<3>(const SlabMesh&, BlockSweepStats&);

}  // namespace rivulet
