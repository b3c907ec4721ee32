#include "jobs/marching_slices.h"

#include <algorithm>
#include <array>

#include "jobs/marching_tables.h"

namespace rivulet {
namespace {

constexpr std::uint32_t kMaxBlockCubes = 128;  // SlicesSettings::validate's limit on block_cubes

}  // namespace

BlockSweepStats march_block(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                            float iso, const LookupCacheView& cache, ConstPositions particles,
                            const SliceScratch& s, const BlockMeshOut& out, bool exhaustive,
                            unsigned empty_neighbours) {
    const MarchingTables& mt = marching_tables();
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    const std::uint32_t n = g.n, n1 = n + 1, cols = n1 * n1;
    const std::int32_t i0 = static_cast<std::int32_t>(bi * n), j0 = static_cast<std::int32_t>(bj * n),
                       k0 = static_cast<std::int32_t>(bk * n);
    BlockSweepStats st;

    std::uint32_t gen = ++*s.generation;
    if (gen == 0) {  // stamps wrapped: clear them once
        std::fill(s.cube_stamp.begin(), s.cube_stamp.end(), 0u);
        std::fill(s.edges.begin(), s.edges.end(), EdgeSlot{0, 0});
        gen = *s.generation = 1;
    }

    // World z of each slice, for corner and column evaluations (padded: column runs read up to four).
    std::array<float, kMaxBlockCubes + 4> column_z{};
    for (std::uint32_t k = 0; k <= n; ++k) column_z[k] = g.cz(k0 + static_cast<std::int32_t>(k));
    auto field = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
        return cache_field(cache, n, i, j, static_cast<std::int32_t>(k), column_z[k], f);
    };
    // F at one corner by the branch-free column kernel (a run of one slice).
    auto corner = [&](std::uint32_t i, std::uint32_t j, std::uint32_t k) {
        float v;
        cache_column(cache, n, i, j, static_cast<std::int32_t>(k), static_cast<std::int32_t>(k),
                     column_z.data() + k, f, &v);
        return v;
    };

    // ---- per-slab todo lists ----
    std::fill(s.todo_count.begin(), s.todo_count.end(), 0u);
    std::uint32_t lowest = n;  // lowest slab that may hold work
    auto push = [&](std::int32_t i, std::int32_t j, std::int32_t k) {
        if (i < 0 || j < 0 || k < 0 || i >= std::int32_t(n) || j >= std::int32_t(n) || k >= std::int32_t(n))
            return;
        const std::uint32_t slab = static_cast<std::uint32_t>(k);
        const std::uint32_t in_slab = static_cast<std::uint32_t>(j) * n + static_cast<std::uint32_t>(i);
        const std::uint32_t c = slab * n * n + in_slab;
        if (s.cube_stamp[c] == gen) return;
        s.cube_stamp[c] = gen;
        // Queued as j << 8 | i (n <= 128): unpacking needs no division by the runtime n.
        s.todo[std::size_t(slab) * n * n + s.todo_count[slab]++] =
            static_cast<std::uint32_t>(j) << 8 | static_cast<std::uint32_t>(i);
        lowest = std::min(lowest, slab);
    };

    // ---- seeds 1: walk down from each particle's nearest corner ----
    std::fill(s.walk_lo.begin(), s.walk_lo.end(), 0);
    std::fill(s.walk_hi.begin(), s.walk_hi.end(), -1);
    // Walks down from local corner (li, lj, lk) (clamped to the top slice); false when that corner is
    // outside the block's columns or outside the fluid.
    auto walk = [&](std::int32_t li, std::int32_t lj, std::int32_t lk) {
        if (li < 0 || lj < 0 || lk < 0 || li > std::int32_t(n) || lj > std::int32_t(n)) return false;
        lk = std::min(lk, std::int32_t(n));
        const std::uint32_t col = static_cast<std::uint32_t>(lj) * n1 + static_cast<std::uint32_t>(li);
        std::int32_t& run_lo = s.walk_lo[col];
        std::int32_t& run_hi = s.walk_hi[col];
        if (lk >= run_lo && lk <= run_hi) return true;  // inside a run already walked
        const auto ui = static_cast<std::uint32_t>(li), uj = static_cast<std::uint32_t>(lj);
        // Corner values four slices at a time downwards (one pass over the column's entries each).
        float run[4];
        std::int32_t run_top = -1, run_bottom = 0;
        auto inside_at = [&](std::int32_t k) {
            if (k > run_top || k < run_bottom) {
                run_top = k, run_bottom = std::max(0, k - 3);
                cache_column(cache, n, ui, uj, run_bottom, run_top, column_z.data() + run_bottom, f, run);
            }
            return run[k - run_bottom] >= iso;
        };
        if (!inside_at(lk)) return false;
        std::int32_t k = lk - 1;
        for (; k >= 0; --k) {
            if (k >= run_lo && k <= run_hi) break;
            if (!inside_at(k)) break;
        }
        if (k >= 0 && k >= run_lo && k <= run_hi) {  // joined the known run: same crossing below
            run_hi = std::max(run_hi, lk);
            return true;
        }
        run_lo = k + 1, run_hi = lk;
        if (k < 0) return true;  // left through the block bottom: the face scan covers it
        for (std::int32_t dj = -1; dj <= 0; ++dj)
            for (std::int32_t di = -1; di <= 0; ++di) push(li + di, lj + dj, k);
        ++st.seeds;
        return true;
    };
    const float half = 0.5f * g.voxel;
    for (std::size_t q = 0; q < particles.size(); ++q) {
        const float x = particles.x[q], y = particles.y[q], z = particles.z[q];
        const std::int32_t li = SliceGrid::cell(x + half, g.ox, g.voxel) - i0,
                           lj = SliceGrid::cell(y + half, g.oy, g.voxel) - j0,
                           lk = SliceGrid::cell(z + half, g.oz, g.voxel) - k0;
        if (walk(li, lj, lk)) continue;
        if (li < 0 || lj < 0 || lk < 0 || li > std::int32_t(n) || lj > std::int32_t(n)) continue;
        // The nearest corner is outside the fluid (a coarse voxel, a thin part): try the other corners
        // of the cube holding the centre.
        const std::int32_t ci = SliceGrid::cell(x, g.ox, g.voxel) - i0,
                           cj = SliceGrid::cell(y, g.oy, g.voxel) - j0,
                           ck = SliceGrid::cell(z, g.oz, g.voxel) - k0;
        for (std::int32_t c = 0; c < 8; ++c)
            if (walk(ci + (c & 1), cj + ((c >> 1) & 1), ck + ((c >> 2) & 1))) break;
    }

    // ---- optional seeds 3: every sign change on every z column (finds empty cavities too) ----
    if (exhaustive)
        for (std::uint32_t j = 0; j <= n; ++j)
            for (std::uint32_t i = 0; i <= n; ++i) {
                bool below = field(i, j, 0) >= iso;
                for (std::uint32_t k = 1; k <= n; ++k) {
                    const bool here = field(i, j, k) >= iso;
                    if (here != below)
                        for (std::int32_t dj = -1; dj <= 0; ++dj)
                            for (std::int32_t di = -1; di <= 0; ++di)
                                push(std::int32_t(i) + di, std::int32_t(j) + dj, std::int32_t(k) - 1);
                    below = here;
                }
            }

    // ---- seeds 2: every block face the surface can cross ----
    // s.faces[w * n1 + u] = 1 where F >= iso on face (a, side), else 0; u and w are the next two axes
    // after a. The x and y faces are made of whole z columns, evaluated a column at a time.
    std::array<float, kMaxBlockCubes + 1> column_f{};
    auto fill_face = [&](std::uint32_t a, std::uint32_t side) {
        if (a == 2) {
            for (std::uint32_t j = 0; j <= n; ++j)
                for (std::uint32_t i = 0; i <= n; ++i)
                    s.faces[j * n1 + i] = corner(i, j, side * n) >= iso ? 1.0f : 0.0f;
            return;
        }
        for (std::uint32_t t = 0; t <= n; ++t) {
            const std::uint32_t i = a == 0 ? side * n : t, j = a == 0 ? t : side * n;
            cache_column(cache, n, i, j, 0, static_cast<std::int32_t>(n), column_z.data(), f,
                         column_f.data());
            // a = 0: u = y (t), w = z; a = 1: u = z, w = x (t).
            for (std::uint32_t k = 0; k <= n; ++k)
                s.faces[a == 0 ? k * n1 + t : t * n1 + k] = column_f[k] >= iso ? 1.0f : 0.0f;
        }
    };
    const std::uint32_t bidx[3] = {bi, bj, bk}, nb[3] = {g.bx, g.by, g.bz};
    for (std::uint32_t a = 0; a < 3; ++a)
        for (std::uint32_t side = 0; side < 2; ++side) {
            if (side == 0 && bidx[a] == 0) continue;                // outer grid face: no surface there
            if (side == 1 && bidx[a] + 1 == nb[a]) continue;        // likewise
            if (empty_neighbours >> (2 * a + side) & 1u) continue;  // F = 0 on the whole face
            const std::uint32_t u = (a + 1) % 3, w = (a + 2) % 3;
            fill_face(a, side);
            for (std::uint32_t cw = 0; cw < n; ++cw)
                for (std::uint32_t cu = 0; cu < n; ++cu) {
                    const bool i00 = s.faces[cw * n1 + cu] != 0.0f, i10 = s.faces[cw * n1 + cu + 1] != 0.0f,
                               i01 = s.faces[(cw + 1) * n1 + cu] != 0.0f,
                               i11 = s.faces[(cw + 1) * n1 + cu + 1] != 0.0f;
                    if (i00 == i10 && i00 == i01 && i00 == i11) continue;
                    std::int32_t cube[3];
                    cube[a] = side ? std::int32_t(n) - 1 : 0;
                    cube[u] = std::int32_t(cu), cube[w] = std::int32_t(cw);
                    push(cube[0], cube[1], cube[2]);
                    ++st.seeds;
                }
        }

    // ---- slice caches ----
    std::int32_t free_count = static_cast<std::int32_t>(n1);
    for (std::uint32_t k = 0; k < n1; ++k) s.slice_slot[k] = -1, s.free_slots[k] = std::int32_t(k);
    std::uint32_t live = 0, lowest_live = n1;
    auto slice = [&](std::uint32_t k) -> float* {
        std::int32_t slot = s.slice_slot[k];
        if (slot < 0) {
            slot = s.free_slots[--free_count];
            s.slice_slot[k] = slot;
            float* v = s.slices.data() + std::size_t(slot) * cols;
            std::fill(v, v + cols, -1.0f);  // F >= 0: negative means not computed yet
            ++st.slice_fills;
            st.peak_slices = std::max(st.peak_slices, ++live);
            lowest_live = std::min(lowest_live, k);
        }
        return s.slices.data() + std::size_t(slot) * cols;
    };
    auto release_below = [&](std::uint32_t k) {
        for (; lowest_live < k; ++lowest_live)
            if (s.slice_slot[lowest_live] >= 0) {
                s.free_slots[free_count++] = s.slice_slot[lowest_live];
                s.slice_slot[lowest_live] = -1;
                --live;
            }
    };

    // ---- the sweep ----
    const std::uint32_t max_vertices =
        static_cast<std::uint32_t>(std::min(out.positions.size() / 3, out.keys.size()));
    const std::uint32_t max_triangles = static_cast<std::uint32_t>(out.triangles.size() / 3);
    for (;;) {
        while (lowest < n && s.todo_count[lowest] == 0) ++lowest;
        if (lowest == n) break;
        const std::uint32_t k = lowest;
        release_below(k);
        const std::uint32_t queued = s.todo[std::size_t(k) * n * n + --s.todo_count[k]];
        const std::uint32_t i = queued & 0xffu, j = queued >> 8;
        ++st.cubes;

        float* lower = slice(k);
        float* upper = slice(k + 1);
        float v[8];
        unsigned mask = 0;
        for (unsigned c = 0; c < 4; ++c) {  // corner c below, c + 4 above
            const std::uint32_t ci = i + (c & 1u), cj = j + ((c >> 1) & 1u), at = cj * n1 + ci;
            if (lower[at] < 0.0f || upper[at] < 0.0f) {
                // A run of up to four slices of the column from the first missing one: one pass over the
                // column's entries, and the cubes above in this column (the sweep's next slabs) mostly
                // find their corners done. Recomputing a known corner gives the same bits.
                const std::uint32_t from = lower[at] < 0.0f ? k : k + 1, to = std::min(from + 3, n);
                float run[4];
                cache_column(cache, n, ci, cj, static_cast<std::int32_t>(from), static_cast<std::int32_t>(to),
                             column_z.data() + from, f, run);
                for (std::uint32_t t = from; t <= to; ++t) slice(t)[at] = run[t - from];
            }
            v[c] = lower[at], v[c + 4] = upper[at];
        }
        for (unsigned c = 0; c < 8; ++c)
            if (v[c] >= iso) mask |= 1u << c;
        const std::uint32_t ntri = mt.triangle_count[mask];
        if (st.triangles + ntri > max_triangles) {
            st.overflow = true;
            return st;
        }
        for (std::uint32_t t = 0; t < ntri * 3; ++t) {
            const std::uint32_t e = static_cast<std::uint32_t>(mt.triangles[mask][t]);
            const std::uint32_t axis = mt.edge_axis[e], lc = mt.edge_corner[e][0], hc = mt.edge_corner[e][1];
            const std::uint32_t li = i + (lc & 1u), lj = j + ((lc >> 1) & 1u), lk = k + ((lc >> 2) & 1u);
            const std::size_t ek = ((std::size_t(lk) * n1 + lj) * n1 + li) * 3 + axis;
            std::uint32_t vid;
            EdgeSlot& slot = s.edges[ek];
            if (slot.stamp == gen) {
                vid = slot.vertex;
            } else {
                if (st.vertices == max_vertices) {
                    st.overflow = true;
                    return st;
                }
                vid = st.vertices++;
                slot = {gen, vid};
                const std::int32_t gi = i0 + std::int32_t(li), gj = j0 + std::int32_t(lj),
                                   gk = k0 + std::int32_t(lk);
                float p[3] = {g.cx(gi), g.cy(gj), g.cz(gk)};
                p[axis] = edge_crossing(p[axis], g.voxel, v[lc], v[hc], iso);
                out.positions[std::size_t(vid) * 3 + 0] = p[0];
                out.positions[std::size_t(vid) * 3 + 1] = p[1];
                out.positions[std::size_t(vid) * 3 + 2] = p[2];
                out.keys[vid] = edge_key(static_cast<std::uint32_t>(gi), static_cast<std::uint32_t>(gj),
                                         static_cast<std::uint32_t>(gk), axis);
            }
            out.triangles[std::size_t(st.triangles) * 3 + t] = vid;
        }
        st.triangles += ntri;
        // Follow the surface across every face it crosses.
        for (std::uint32_t face = 0; face < 6; ++face) {
            const unsigned fm = mt.face_corners[face], m = mask & fm;
            if (m == 0 || m == fm) continue;
            std::int32_t c[3] = {std::int32_t(i), std::int32_t(j), std::int32_t(k)};
            c[face / 2] += (face & 1u) ? 1 : -1;
            push(c[0], c[1], c[2]);
        }
    }
    return st;
}

}  // namespace rivulet
