#include "jobs/marching_slices.h"

#include <algorithm>
#include <array>
#include <atomic>

#include "jobs/cpu_dispatch.h"
#include "jobs/marching_tables.h"
#include "jobs/simd4.h"

namespace rivulet {
namespace {

constexpr std::uint32_t kMaxBlockCubes = 128;  // SlicesSettings::validate's limit on block_cubes

// The sweep of one block, built twice (march_block): `RunLanes` slices per column-kernel pass in the
// seed walks and the x/y face scans, whose runs are long (8 in the AVX2 build, 4 in the baseline). The
// sweep's own runs stay at four slices: it rarely needs more of a column. Either build gives the same
// bits (cache_column).
template <int RunLanes>
RIVULET_INLINE BlockSweepStats march_block_body(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj,
                                                std::uint32_t bk, float iso, const LookupCacheView& cache,
                                                ConstPositions particles, const SliceScratch& s,
                                                const BlockMeshOut& out, bool exhaustive,
                                                unsigned empty_neighbours, const SharedFaces& shared) {
    const MarchingTables& mt = marching_tables();
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    const std::uint32_t n = g.n, n1 = n + 1, cols = n1 * n1;
    const std::int32_t i0 = static_cast<std::int32_t>(bi * n), j0 = static_cast<std::int32_t>(bj * n),
                       k0 = static_cast<std::int32_t>(bk * n);
    BlockSweepStats st;

    std::uint32_t gen = ++*s.generation;
    if (gen == 0) {  // stamps wrapped: clear them once
        std::fill(s.cube_stamp.begin(), s.cube_stamp.end(), 0u);
        std::fill(s.edges.begin(), s.edges.end(), 0u);  // generation 1 restarts the tags mid-cycle
        gen = *s.generation = 1;
    }
    const std::uint32_t tag = edge_tag(gen);
    if (tag == 1) std::fill(s.edges.begin(), s.edges.end(), 0u);  // a new cycle of edge tags
    const std::uint32_t live_tag = tag << kEdgeVertexBits, vertex_bits = (1u << kEdgeVertexBits) - 1;

    // World z of each slice, for corner and column evaluations (padded: column runs read up to eight).
    std::array<float, kMaxBlockCubes + 8> column_z{};
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
    // Cube (i, j, k) has stamp (k+1, j+1, i+1) in the bordered array; slab k's list is todo row k + 1,
    // whose count is count[k + 1]. Queueing is branch-free: the entry is always written at the list's
    // end (one spare slot per row) and kept only when the cube is in the block and new.
    const std::uint32_t p1 = n + 2, slab_cap = n * n + 1;
    std::uint32_t* const stamp = s.cube_stamp.data();
    std::uint32_t* const todo = s.todo.data();
    std::uint32_t* const count = s.todo_count.data();
    std::fill(count, count + p1, 0u);
    std::int32_t lowest = static_cast<std::int32_t>(n);  // lowest slab that may hold work
    // Stamps cube `at` (bordered index) when `take` and it is not stamped yet; 1 when it was new.
    auto claim = [&](std::uint32_t at, bool take) {
        const std::uint32_t old = stamp[at];
        const bool fresh = take && old != gen;
        stamp[at] = fresh ? gen : old;
        return fresh ? 1u : 0u;
    };
    auto push = [&](std::int32_t i, std::int32_t j, std::int32_t k) {  // i, j, k in [-1, n]
        const std::uint32_t row = static_cast<std::uint32_t>(k + 1);
        const std::uint32_t at =
            (row * p1 + static_cast<std::uint32_t>(j + 1)) * p1 + static_cast<std::uint32_t>(i + 1);
        const bool in_block = static_cast<std::uint32_t>(i) < n && static_cast<std::uint32_t>(j) < n &&
                              static_cast<std::uint32_t>(k) < n;
        const std::uint32_t fresh = claim(at, in_block);
        // Queued as j << 8 | i (n <= 128): unpacking needs no division by the runtime n.
        todo[row * slab_cap + count[row]] =
            static_cast<std::uint32_t>(j) << 8 | static_cast<std::uint32_t>(i & 0xff);
        count[row] += fresh;
        lowest = fresh && k < lowest ? k : lowest;
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
        // Corner values RunLanes slices at a time downwards (one pass over the column's entries each).
        float run[RunLanes];
        std::int32_t run_top = -1, run_bottom = 0;
        auto inside_at = [&](std::int32_t k) {
            if (k > run_top || k < run_bottom) {
                run_top = k, run_bottom = std::max(0, k - (RunLanes - 1));
                cache_column<RunLanes>(cache, n, ui, uj, run_bottom, run_top, column_z.data() + run_bottom, f,
                                       run);
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
    // Corners a particle can reach: its cell c reaches corner planes [c - reach, c + reach + 1] on each
    // axis, so the block's particles bound the corners where F can be non-zero; elsewhere F = 0 < iso.
    std::int32_t near_lo[3] = {std::int32_t(n1), std::int32_t(n1), std::int32_t(n1)},
                 near_hi[3] = {-1, -1, -1};
    for (std::size_t q = 0; q < particles.size(); ++q) {
        const std::int32_t c[3] = {SliceGrid::cell(particles.x[q], g.ox, g.voxel) - i0,
                                   SliceGrid::cell(particles.y[q], g.oy, g.voxel) - j0,
                                   SliceGrid::cell(particles.z[q], g.oz, g.voxel) - k0};
        for (int a = 0; a < 3; ++a)
            near_lo[a] = std::min(near_lo[a], c[a] - g.reach),
            near_hi[a] = std::max(near_hi[a], c[a] + g.reach + 1);
    }
    for (int a = 0; a < 3; ++a)
        near_lo[a] = std::max(near_lo[a], 0), near_hi[a] = std::min(near_hi[a], std::int32_t(n));
    // Face (a, side) as bit rows: bit u of row w is set where F >= iso (u, w the next two axes after a),
    // `words` 64-bit words per row plus a zero word, so a row shifted by one bit reads its neighbour.
    const std::uint32_t words = (n1 + 63) / 64, stride = words + 1;
    std::array<float, kMaxBlockCubes + 1> column_f{};
    auto fill_face = [&](std::uint32_t a, std::uint32_t side, std::uint64_t* bits) {
        auto set_bit = [bits, stride](std::uint32_t row, std::uint32_t bit) {
            bits[row * stride + bit / 64] |= std::uint64_t(1) << (bit % 64);
        };
        std::fill(bits, bits + std::size_t(n1) * stride, std::uint64_t(0));
        const std::uint32_t plane = side * n;
        if (a == 2) {
            for (std::int32_t j = near_lo[1]; j <= near_hi[1]; ++j)
                for (std::int32_t i = near_lo[0]; i <= near_hi[0]; ++i)
                    if (corner(std::uint32_t(i), std::uint32_t(j), plane) >= iso)
                        set_bit(std::uint32_t(j), std::uint32_t(i));
            return;
        }
        // The x and y faces are made of whole z columns, evaluated a column at a time.
        const std::int32_t k_lo = near_lo[2], k_hi = near_hi[2];
        for (std::int32_t t = near_lo[a == 0 ? 1 : 0]; t <= near_hi[a == 0 ? 1 : 0]; ++t) {
            const std::uint32_t ut = static_cast<std::uint32_t>(t);
            const std::uint32_t i = a == 0 ? plane : ut, j = a == 0 ? ut : plane;
            cache_column<RunLanes>(cache, n, i, j, k_lo, k_hi, column_z.data() + k_lo, f, column_f.data());
            // a = 0: u = y (t), w = z; a = 1: u = z, w = x (t).
            for (std::int32_t k = k_lo; k <= k_hi; ++k)
                if (column_f[std::size_t(k - k_lo)] >= iso) {
                    if (a == 0)
                        set_bit(std::uint32_t(k), ut);
                    else
                        set_bit(ut, std::uint32_t(k));
                }
        }
    };
    // The face's bit rows: published by the neighbour, or scanned here (and published when this block
    // claims the face first).
    auto face_bits = [&](std::uint32_t a, std::uint32_t side) -> const std::uint64_t* {
        const SharedFace& sf = shared[2 * a + side];
        if (sf.state != nullptr) {
            std::atomic_ref<std::uint32_t> state(*sf.state);
            std::uint32_t seen = state.load(std::memory_order_acquire);
            if (seen == kFaceDone) return sf.bits;
            if (seen == kFaceFree &&
                state.compare_exchange_strong(seen, kFaceBusy, std::memory_order_acquire)) {
                fill_face(a, side, sf.bits);
                state.store(kFaceDone, std::memory_order_release);
                return sf.bits;
            }
        }
        fill_face(a, side, s.face_bits.data());
        return s.face_bits.data();
    };
    const std::uint32_t bidx[3] = {bi, bj, bk}, nb[3] = {g.bx, g.by, g.bz};
    const std::uint64_t last_cells = (n % 64) ? (std::uint64_t(1) << (n % 64)) - 1 : ~std::uint64_t(0);
    for (std::uint32_t a = 0; a < 3; ++a)
        for (std::uint32_t side = 0; side < 2; ++side) {
            if (side == 0 && bidx[a] == 0) continue;                // outer grid face: no surface there
            if (side == 1 && bidx[a] + 1 == nb[a]) continue;        // likewise
            if (empty_neighbours >> (2 * a + side) & 1u) continue;  // F = 0 on the whole face
            const std::int32_t plane = static_cast<std::int32_t>(side * n);
            if (plane < near_lo[a] || plane > near_hi[a]) continue;  // no particle reaches it: F = 0
            const std::uint32_t u = (a + 1) % 3, w = (a + 2) % 3;
            const std::uint64_t* const bits = face_bits(a, side);
            // A face cell is crossed when its four corners (bits u, u + 1 of rows w, w + 1) differ.
            for (std::uint32_t cw = 0; cw < n; ++cw) {
                const std::uint64_t* r0 = bits + cw * stride;
                const std::uint64_t* r1 = r0 + stride;
                for (std::uint32_t t = 0; t < words && t * 64 < n; ++t) {
                    const std::uint64_t a0 = r0[t], a1 = r0[t] >> 1 | r0[t + 1] << 63;
                    const std::uint64_t b0 = r1[t], b1 = r1[t] >> 1 | r1[t + 1] << 63;
                    std::uint64_t crossed = (a0 | a1 | b0 | b1) & ~(a0 & a1 & b0 & b1);
                    if ((t + 1) * 64 >= n) crossed &= last_cells;  // cells u < n only
                    for (; crossed != 0; crossed &= crossed - 1) {
                        const std::uint32_t cu =
                            t * 64 + static_cast<std::uint32_t>(__builtin_ctzll(crossed));
                        std::int32_t cube[3];
                        cube[a] = side ? std::int32_t(n) - 1 : 0;
                        cube[u] = std::int32_t(cu), cube[w] = std::int32_t(cw);
                        push(cube[0], cube[1], cube[2]);
                        ++st.seeds;
                    }
                }
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
    // Cube-relative offsets of the 12 edges' slots.
    std::uint32_t edge_offset[12];
    for (std::uint32_t e = 0; e < 12; ++e) {
        const std::uint32_t lc = mt.edge_corner[e][0];
        edge_offset[e] =
            (((lc >> 2) & 1u) * n1 * n1 + ((lc >> 1) & 1u) * n1 + (lc & 1u)) * 3 + mt.edge_axis[e];
    }
    const std::int32_t top = static_cast<std::int32_t>(n);
    const simd::F4 iso4 = simd::splat(iso);
    for (;;) {
        while (lowest < top && count[lowest + 1] == 0) ++lowest;
        if (lowest >= top) break;
        const std::uint32_t k = static_cast<std::uint32_t>(lowest);
        release_below(k);
        const std::uint32_t queued = todo[(k + 1) * slab_cap + --count[k + 1]];
        const std::uint32_t i = queued & 0xffu, j = queued >> 8;
        ++st.cubes;

        float* lower = slice(k);
        float* upper = slice(k + 1);
        // The cube's corners c = 0..3 (i + (c & 1), j + (c >> 1)) below and c + 4 above, four to a vector.
        const std::uint32_t corner0 = j * n1 + i;
        simd::F4 below = simd::load_pairs(lower + corner0, lower + corner0 + n1);
        simd::F4 above = simd::load_pairs(upper + corner0, upper + corner0 + n1);
        if ((simd::sign_mask(below) | simd::sign_mask(above)) != 0) {  // some corner not computed yet
            for (unsigned c = 0; c < 4; ++c) {
                const std::uint32_t ci = i + (c & 1u), cj = j + (c >> 1), cat = cj * n1 + ci;
                if (lower[cat] >= 0.0f && upper[cat] >= 0.0f) continue;
                // A run of up to four slices of the column from the first missing one: one pass over the
                // column's entries, and the cubes above in this column (the sweep's next slabs) mostly
                // find their corners done. Recomputing a known corner gives the same bits.
                const std::uint32_t from = lower[cat] < 0.0f ? k : k + 1, to = std::min(from + 3, n);
                float run[4];
                cache_column(cache, n, ci, cj, static_cast<std::int32_t>(from), static_cast<std::int32_t>(to),
                             column_z.data() + from, f, run);
                for (std::uint32_t t = from; t <= to; ++t) slice(t)[cat] = run[t - from];
            }
            below = simd::load_pairs(lower + corner0, lower + corner0 + n1);
            above = simd::load_pairs(upper + corner0, upper + corner0 + n1);
        }
        const unsigned mask = simd::geq_mask(below, iso4) | simd::geq_mask(above, iso4) << 4;
        float v[8];
        simd::store(v, below), simd::store(v + 4, above);
        const std::uint32_t ntri = mt.triangle_count[mask];
        if (st.triangles + ntri > max_triangles) {
            st.overflow = true;
            return st;
        }
        const std::size_t base = ((std::size_t(k) * n1 + j) * n1 + i) * 3;
        std::uint32_t vid[12];
        for (std::uint32_t q = 0; q < mt.edge_count[mask]; ++q) {
            const auto e = static_cast<std::uint32_t>(mt.edge_order[mask][q]);
            std::uint32_t& slot = s.edges[base + edge_offset[e]];
            if ((slot & ~vertex_bits) == live_tag) {
                vid[e] = slot & vertex_bits;
                continue;
            }
            if (st.vertices == max_vertices) {
                st.overflow = true;
                return st;
            }
            const std::uint32_t id = st.vertices++;
            slot = live_tag | id;
            vid[e] = id;
            const std::uint32_t axis = mt.edge_axis[e], lc = mt.edge_corner[e][0], hc = mt.edge_corner[e][1];
            const std::int32_t gi = i0 + std::int32_t(i + (lc & 1u)),
                               gj = j0 + std::int32_t(j + ((lc >> 1) & 1u)),
                               gk = k0 + std::int32_t(k + ((lc >> 2) & 1u));
            float p[3] = {g.cx(gi), g.cy(gj), g.cz(gk)};
            p[axis] = edge_crossing(p[axis], g.voxel, v[lc], v[hc], iso);
            out.positions[std::size_t(id) * 3 + 0] = p[0];
            out.positions[std::size_t(id) * 3 + 1] = p[1];
            out.positions[std::size_t(id) * 3 + 2] = p[2];
            out.keys[id] = edge_key(static_cast<std::uint32_t>(gi), static_cast<std::uint32_t>(gj),
                                    static_cast<std::uint32_t>(gk), axis);
        }
        std::uint32_t* tri = out.triangles.data() + std::size_t(st.triangles) * 3;
        for (std::uint32_t t = 0; t < ntri * 3; ++t)
            tri[t] = vid[static_cast<std::uint32_t>(mt.triangles[mask][t])];
        st.triangles += ntri;
        // Follow the surface across every face it crosses, queueing neighbours in the order -x, +x, -y,
        // +y (this slab), -z (the slab below), +z (above); the same lists as six push calls, with the
        // slab's count updated once.
        const unsigned crossed = mt.crossed_faces[mask];
        const std::uint32_t row = k + 1, at = (row * p1 + j + 1) * p1 + i + 1, layer = p1 * p1;
        const std::uint32_t mx = claim(at - 1, (crossed & 1u) && i > 0),
                            px = claim(at + 1, (crossed & 2u) && i + 1 < n),
                            my = claim(at - p1, (crossed & 4u) && j > 0),
                            py = claim(at + p1, (crossed & 8u) && j + 1 < n),
                            mz = claim(at - layer, (crossed & 16u) && k > 0),
                            pz = claim(at + layer, (crossed & 32u) && k + 1 < n);
        std::uint32_t* list = todo + row * slab_cap;
        std::uint32_t c = count[row];
        list[c] = j << 8 | ((i - 1) & 0xffu), c += mx;  // i - 1 wraps when i = 0: written, not kept
        list[c] = j << 8 | (i + 1), c += px;
        list[c] = (j - 1) << 8 | i, c += my;
        list[c] = (j + 1) << 8 | i, c += py;
        count[row] = c;
        todo[(row - 1) * slab_cap + count[row - 1]] = j << 8 | i, count[row - 1] += mz;
        todo[(row + 1) * slab_cap + count[row + 1]] = j << 8 | i, count[row + 1] += pz;
        lowest = mz ? lowest - 1 : lowest;  // lowest == k here
    }
    return st;
}

}  // namespace

BlockSweepStats march_block_baseline(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                                     float iso, const LookupCacheView& cache, ConstPositions particles,
                                     const SliceScratch& s, const BlockMeshOut& out, bool exhaustive,
                                     unsigned empty_neighbours, const SharedFaces& shared) {
    return march_block_body<4>(g, bi, bj, bk, iso, cache, particles, s, out, exhaustive, empty_neighbours,
                               shared);
}

// flatten: the body's lambdas and the column kernel are inlined here, so they are built for AVX2 too.
RIVULET_AVX2 [[gnu::flatten]] static BlockSweepStats march_block_avx2(
    const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk, float iso,
    const LookupCacheView& cache, ConstPositions particles, const SliceScratch& s, const BlockMeshOut& out,
    bool exhaustive, unsigned empty_neighbours, const SharedFaces& shared) {
    return march_block_body<8>(g, bi, bj, bk, iso, cache, particles, s, out, exhaustive, empty_neighbours,
                               shared);
}

BlockSweepStats march_block(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                            float iso, const LookupCacheView& cache, ConstPositions particles,
                            const SliceScratch& s, const BlockMeshOut& out, bool exhaustive,
                            unsigned empty_neighbours, const SharedFaces& shared) {
    if (cpu_has_avx2())
        return march_block_avx2(g, bi, bj, bk, iso, cache, particles, s, out, exhaustive, empty_neighbours,
                                shared);
    return march_block_baseline(g, bi, bj, bk, iso, cache, particles, s, out, exhaustive, empty_neighbours,
                                shared);
}

}  // namespace rivulet
