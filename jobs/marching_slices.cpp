#include "jobs/marching_slices.h"

#include <algorithm>
#include <array>
#include <atomic>

#include "jobs/bit_rows.h"
#include "jobs/cpu_dispatch.h"
#include "jobs/marching_tables.h"
#include "jobs/slab_mesh.h"

namespace rivulet {
namespace {

// The sweep of one block in the stages of marching_slices.h: seeds from particles, seeds from every
// column (optional), seeds from the block faces, then the sweep itself. One object per block, on the
// stack; its stages share the block's queue. Built twice (march_block): `RunLanes` slices per
// column-kernel pass in the seed walks, the x/y face scans and the sweep's corner runs (8 in the AVX2
// build, 4 in the baseline); every member is always inlined, so each build compiles all of it. Either
// build gives the same bits (cache_column).
template <int W, int RunLanes, class Cache>
struct BlockSweep {
    using Row = BitRow<W>;

    const BlockSweepContext& block;
    const Cache& cache;
    const SliceGrid& g;
    const SliceScratch& s;
    const float iso;
    const SliceKernel f;
    const std::uint32_t n, n1;
    const std::int32_t i0, j0, k0;
    const Row cube_row;
    BlockSweepStats st;

    // World coordinates of the block's corner planes, as every corner computes them (SliceGrid::cx/cy/cz);
    // z padded: column runs read up to eight slices.
    std::array<float, kMaxBlockCubes + 1> plane_x{}, plane_y{};
    std::array<float, kMaxBlockCubes + 8> column_z{};
    std::array<float, kMaxBlockCubes + 8>
        column_f{};  // one column's values; padded: whole vectors are stored

    // The queue: per slab, rows of cubes queued (the todo list) and ever queued.
    std::uint64_t* const queued;  // slab k, row j: (k * n + j) * W
    std::uint64_t* const seen;
    std::int32_t* const range_lo;  // rows of slab k that may hold queued cubes
    std::int32_t* const range_hi;
    std::int32_t lowest;  // lowest slab that may hold work

    RIVULET_INLINE BlockSweep(const BlockSweepContext& b, const Cache& c)
        : block(b),
          cache(c),
          g(*b.grid),
          s(b.scratch),
          iso(b.iso),
          f(SliceKernel::from_rc(g.rc)),
          n(g.n),
          n1(g.n + 1),
          i0(static_cast<std::int32_t>(b.bi * g.n)),
          j0(static_cast<std::int32_t>(b.bj * g.n)),
          k0(static_cast<std::int32_t>(b.bk * g.n)),
          cube_row(low_bits<W>(g.n)),
          queued(s.slab_rows.data()),
          seen(queued + std::size_t(n) * n * W),
          range_lo(s.slab_range.data()),
          range_hi(range_lo + n),
          lowest(static_cast<std::int32_t>(n)) {
        for (std::uint32_t k = 0; k <= n; ++k) {
            plane_x[k] = g.cx(i0 + static_cast<std::int32_t>(k));
            plane_y[k] = g.cy(j0 + static_cast<std::int32_t>(k));
            column_z[k] = g.cz(k0 + static_cast<std::int32_t>(k));
        }
        std::fill(queued, queued + 2 * std::size_t(n) * n * W, std::uint64_t(0));
        std::fill(range_lo, range_lo + n, std::int32_t(n));
        std::fill(range_hi, range_hi + n, std::int32_t(-1));
    }

    RIVULET_INLINE BlockSweepStats run() {
        seed_from_particles();
        if (block.exhaustive) seed_from_columns();
        seed_from_faces();
        sweep();
        return st;
    }

    // ---- the queue ----

    // Row r of rows of W words from base.
    RIVULET_INLINE static Row row(const std::uint64_t* base, std::size_t r) {
        return load_row<W>(base + r * W);
    }

    // Queues the cubes `bits` of slab k, row j that were never queued.
    RIVULET_INLINE void queue_row(std::uint32_t k, std::uint32_t j, Row bits) {
        std::uint64_t* const seen_at = seen + (std::size_t(k) * n + j) * W;
        const Row was = load_row<W>(seen_at), fresh = and_not(bits, was);
        if (!any(fresh)) return;
        store_row<W>(seen_at, was | fresh);
        std::uint64_t* const queued_at = queued + (std::size_t(k) * n + j) * W;
        store_row<W>(queued_at, load_row<W>(queued_at) | fresh);
        range_lo[k] = std::min(range_lo[k], std::int32_t(j));
        range_hi[k] = std::max(range_hi[k], std::int32_t(j));
        lowest = std::min(lowest, std::int32_t(k));
    }

    // Queues one cube; a cube outside the block is skipped.
    RIVULET_INLINE void push(std::int32_t i, std::int32_t j, std::int32_t k) {
        if (static_cast<std::uint32_t>(i) >= n || static_cast<std::uint32_t>(j) >= n ||
            static_cast<std::uint32_t>(k) >= n)
            return;
        queue_row(std::uint32_t(k), std::uint32_t(j), single_bit<W>(std::uint32_t(i)));
    }

    // Queues the four cubes around the z edge from corner (i, j, slab) to (i, j, slab + 1).
    RIVULET_INLINE void push_around_z_edge(std::int32_t i, std::int32_t j, std::int32_t slab) {
        for (std::int32_t dj = -1; dj <= 0; ++dj)
            for (std::int32_t di = -1; di <= 0; ++di) push(i + di, j + dj, slab);
    }

    // F at one corner by the branch-free column kernel (a run of one slice).
    RIVULET_INLINE float corner(std::uint32_t i, std::uint32_t j, std::uint32_t k) const {
        float v[4];
        cache_column(cache, n, i, j, static_cast<std::int32_t>(k), static_cast<std::int32_t>(k),
                     column_z.data() + k, f, v);
        return v[0];
    }

    // ---- seeds 1: walk from each particle's nearest corner to the surface ----
    // The walk goes down (as in the thesis) or up, towards the nearer of the block's bottom and top faces:
    // either finds the crossing that bounds the particle's inside region, or leaves the block through a
    // face whose scan (seeds 2) finds that region's surface; walks in deep fluid are half as long.

    // Corner (li, lj, lk) is outside the block's columns, or below the block.
    RIVULET_INLINE bool off_columns(std::int32_t li, std::int32_t lj, std::int32_t lk) const {
        return li < 0 || lj < 0 || lk < 0 || li > std::int32_t(n) || lj > std::int32_t(n);
    }

    // Walks from local corner (li, lj, lk) (clamped to the top slice); false when that corner is outside
    // the block's columns or outside the fluid. Per column, walk_lo/hi hold a run of corners walked through
    // (all inside, and their walk's end known): a walk that starts in it or reaches it is done.
    RIVULET_INLINE bool walk(std::int32_t li, std::int32_t lj, std::int32_t lk) {
        if (off_columns(li, lj, lk)) return false;
        lk = std::min(lk, std::int32_t(n));
        const std::uint32_t col = static_cast<std::uint32_t>(lj) * n1 + static_cast<std::uint32_t>(li);
        std::int32_t& run_lo = s.walk_lo[col];
        std::int32_t& run_hi = s.walk_hi[col];
        auto in_run = [&](std::int32_t k) { return k >= run_lo && k <= run_hi; };
        if (in_run(lk)) return true;
        const auto ui = static_cast<std::uint32_t>(li), uj = static_cast<std::uint32_t>(lj);
        const bool up = 2 * lk > std::int32_t(n);
        const std::int32_t step = up ? 1 : -1;
        // Corner values RunLanes slices at a time in the walk's direction (one pass over the column's
        // entries each).
        float run[RunLanes];
        std::int32_t run_top = -1, run_bottom = 0;
        auto inside_at = [&](std::int32_t k) {
            if (k > run_top || k < run_bottom) {
                if (up)
                    run_bottom = k, run_top = std::min(std::int32_t(n), k + (RunLanes - 1));
                else
                    run_top = k, run_bottom = std::max(0, k - (RunLanes - 1));
                cache_column<RunLanes>(cache, n, ui, uj, run_bottom, run_top, column_z.data() + run_bottom, f,
                                       run);
            }
            return run[k - run_bottom] >= iso;
        };
        if (!inside_at(lk)) return false;
        std::int32_t k = lk + step;
        for (; k >= 0 && k <= std::int32_t(n); k += step)
            if (in_run(k) || !inside_at(k)) break;
        const bool left = k < 0 || k > std::int32_t(n);  // through a face: its scan covers the region
        if (!left && in_run(k)) {                        // joined the known run: the same end
            run_lo = std::min(run_lo, lk), run_hi = std::max(run_hi, lk);
            return true;
        }
        run_lo = std::min(lk, k - step), run_hi = std::max(lk, k - step);
        if (left) return true;
        push_around_z_edge(li, lj, up ? k - 1 : k);  // the crossed edge runs from slice k - 1 or k up
        ++st.seeds;
        return true;
    }

    RIVULET_INLINE void seed_from_particles() {
        std::fill(s.walk_lo.begin(), s.walk_lo.end(), 0);
        std::fill(s.walk_hi.begin(), s.walk_hi.end(), -1);
        const ConstPositions& particles = block.particles;
        const float half = 0.5f * g.voxel;
        for (std::size_t q = 0; q < particles.size(); ++q) {
            const float x = particles.x[q], y = particles.y[q], z = particles.z[q];
            const std::int32_t li = SliceGrid::cell(x + half, g.ox, g.inv_voxel) - i0,
                               lj = SliceGrid::cell(y + half, g.oy, g.inv_voxel) - j0,
                               lk = SliceGrid::cell(z + half, g.oz, g.inv_voxel) - k0;
            if (walk(li, lj, lk)) continue;
            if (off_columns(li, lj, lk)) continue;
            // The nearest corner is outside the fluid (a coarse voxel, a thin part): try the other corners
            // of the cube holding the centre.
            const std::int32_t ci = SliceGrid::cell(x, g.ox, g.inv_voxel) - i0,
                               cj = SliceGrid::cell(y, g.oy, g.inv_voxel) - j0,
                               ck = SliceGrid::cell(z, g.oz, g.inv_voxel) - k0;
            for (std::int32_t c = 0; c < 8; ++c)
                if (walk(ci + (c & 1), cj + ((c >> 1) & 1), ck + ((c >> 2) & 1))) break;
        }
    }

    // ---- optional seeds 3: every sign change on every z column (finds empty cavities too) ----
    RIVULET_INLINE void seed_from_columns() {
        for (std::uint32_t j = 0; j <= n; ++j)
            for (std::uint32_t i = 0; i <= n; ++i) {
                cache_column<RunLanes>(cache, n, i, j, 0, std::int32_t(n), column_z.data(), f,
                                       column_f.data());
                bool below = column_f[0] >= iso;
                for (std::uint32_t k = 1; k <= n; ++k) {
                    const bool here = column_f[k] >= iso;
                    if (here != below)
                        push_around_z_edge(std::int32_t(i), std::int32_t(j), std::int32_t(k) - 1);
                    below = here;
                }
            }
    }

    // ---- seeds 2: every block face the surface can cross ----

    // Local corners a particle can reach, per axis: its cell c reaches corner planes [c - reach, c + reach
    // + 1], so the block's particles bound the corners where F can be non-zero; elsewhere F = 0 < iso.
    struct Reach {
        std::int32_t lo[3], hi[3];
    };
    RIVULET_INLINE Reach particle_reach() const {
        Reach r{{std::int32_t(n1), std::int32_t(n1), std::int32_t(n1)}, {-1, -1, -1}};
        const ConstPositions& particles = block.particles;
        if (!particles.x.empty()) {
            // SliceGrid::cell is monotone, so the cells of the lowest and highest coordinates bound them all.
            const std::span<const float> axes[3] = {particles.x, particles.y, particles.z};
            const float origin[3] = {g.ox, g.oy, g.oz};
            const std::int32_t block_origin[3] = {i0, j0, k0};
            for (int a = 0; a < 3; ++a) {
                const auto [lo, hi] = std::minmax_element(axes[a].begin(), axes[a].end());
                r.lo[a] = SliceGrid::cell(*lo, origin[a], g.inv_voxel) - block_origin[a] - g.reach;
                r.hi[a] = SliceGrid::cell(*hi, origin[a], g.inv_voxel) - block_origin[a] + g.reach + 1;
            }
        }
        for (int a = 0; a < 3; ++a)
            r.lo[a] = std::max(r.lo[a], 0), r.hi[a] = std::min(r.hi[a], std::int32_t(n));
        return r;
    }

    // Face (a, side) as bit rows of W words: bit u of row w is set where F >= iso (u, w the next two axes
    // after a).
    RIVULET_INLINE void fill_face(std::uint32_t a, std::uint32_t side, const Reach& near,
                                  std::uint64_t* bits) {
        auto set_bit = [bits](std::uint32_t r, std::uint32_t bit) {
            bits[r * W + bit / 64] |= std::uint64_t(1) << (bit % 64);
        };
        std::fill(bits, bits + std::size_t(n1) * W, std::uint64_t(0));
        const std::uint32_t plane = side * n;
        if (a == 2) {
            for (std::int32_t j = near.lo[1]; j <= near.hi[1]; ++j)
                for (std::int32_t i = near.lo[0]; i <= near.hi[0]; ++i)
                    if (corner(std::uint32_t(i), std::uint32_t(j), plane) >= iso)
                        set_bit(std::uint32_t(j), std::uint32_t(i));
            return;
        }
        // The x and y faces are made of whole z columns, evaluated a column at a time.
        const std::int32_t k_lo = near.lo[2], k_hi = near.hi[2];
        for (std::int32_t t = near.lo[a == 0 ? 1 : 0]; t <= near.hi[a == 0 ? 1 : 0]; ++t) {
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
    }

    // The face's bit rows: published by the neighbour, or scanned here (and published when this block
    // claims the face first).
    RIVULET_INLINE const std::uint64_t* face_bits(std::uint32_t a, std::uint32_t side, const Reach& near) {
        const SharedFace& sf = block.shared[2 * a + side];
        if (sf.state != nullptr) {
            std::atomic_ref<std::uint32_t> state(*sf.state);
            std::uint32_t now = state.load(std::memory_order_acquire);
            if (now == kFaceDone) return sf.bits;
            if (now == kFaceFree &&
                state.compare_exchange_strong(now, kFaceBusy, std::memory_order_acquire)) {
                fill_face(a, side, near, sf.bits);
                state.store(kFaceDone, std::memory_order_release);
                return sf.bits;
            }
        }
        fill_face(a, side, near, s.face_bits.data());
        return s.face_bits.data();
    }

    RIVULET_INLINE void seed_from_faces() {
        const Reach near = particle_reach();
        const std::uint32_t bidx[3] = {block.bi, block.bj, block.bk}, nb[3] = {g.bx, g.by, g.bz};
        for (std::uint32_t a = 0; a < 3; ++a)
            for (std::uint32_t side = 0; side < 2; ++side) {
                if (side == 0 && bidx[a] == 0) continue;          // outer grid face: no surface there
                if (side == 1 && bidx[a] + 1 == nb[a]) continue;  // likewise
                if (block.empty_neighbours >> (2 * a + side) & 1u) continue;  // F = 0 on the whole face
                const std::int32_t plane = static_cast<std::int32_t>(side * n);
                if (plane < near.lo[a] || plane > near.hi[a]) continue;  // no particle reaches it: F = 0
                const std::uint64_t* const bits = face_bits(a, side, near);
                // A face cell is crossed when its four corners (bits u, u + 1 of rows w, w + 1) differ; u, w
                // are the next two axes after a.
                for (std::uint32_t cw = 0; cw < n; ++cw) {
                    const Row r0 = row(bits, cw), r1 = row(bits, cw + 1);
                    const Row crossed = mixed(r0, shr1(r0), r1, shr1(r1)) & cube_row;  // cells u < n only
                    st.seeds += popcount(crossed);
                    const std::uint32_t edge_cube = side ? n - 1 : 0;
                    if (a == 2) {  // u = x, w = y: a row of cubes
                        queue_row(edge_cube, cw, crossed);
                        continue;
                    }
                    for_each_bit(crossed, [&](std::uint32_t cu) {
                        if (a == 0)  // u = y, w = z
                            queue_row(cw, cu, single_bit<W>(edge_cube));
                        else  // a = 1: u = z, w = x
                            queue_row(cu, edge_cube, single_bit<W>(cw));
                    });
                }
            }
    }

    // ---- the sweep: the lowest slab with queued cubes first ----
    RIVULET_INLINE void sweep() {
        SliceCaches slices(*this);
        std::uint32_t edge_offset[12];
        SlabMesh mesh = slab_mesh(edge_offset);
        std::uint64_t* const frontier = s.work_rows.data();
        std::uint64_t* const visit = frontier + std::size_t(n) * W;
        std::fill(visit, visit + std::size_t(n) * W, std::uint64_t(0));
        const std::int32_t top = static_cast<std::int32_t>(n);
        for (;;) {
            while (lowest < top && range_lo[lowest] > range_hi[lowest]) ++lowest;
            if (lowest >= top) break;
            const std::uint32_t k = static_cast<std::uint32_t>(lowest);
            slices.release_below(k);
            for (std::uint32_t t = k; t <= std::min(k + std::uint32_t(RunLanes), n); ++t) slices.take(t);
            const std::uint64_t* const in_lo = slices.inside_rows(k);
            const std::uint64_t* const in_hi = slices.inside_rows(k + 1);
            std::int32_t visit_lo = top, visit_hi = -1;
            flood_slab(k, slices, frontier, visit, visit_lo, visit_hi);
            if (visit_lo > visit_hi) continue;

            mesh.k = k, mesh.lower = slices.value[k], mesh.upper = slices.value[k + 1];
            mesh.inside_lower = in_lo, mesh.inside_upper = in_hi;
            mesh.visit = visit, mesh.row_lo = visit_lo, mesh.row_hi = visit_hi;
            if (!create_slab_vertices<W>(mesh, st) || !write_slab_triangles<W>(mesh, st)) return;
            std::fill(visit + std::size_t(visit_lo) * W, visit + std::size_t(visit_hi + 1) * W,
                      std::uint64_t(0));
        }
    }

    // Slice caches: corner values, with rows of the corners computed and inside, taken from the pool of
    // SliceScratch::slices when a slab first needs them and given back once the sweep is above them.
    struct SliceCaches {
        BlockSweep& b;
        std::uint64_t* const computed;  // slice t, row r: (t * n1 + r) * W
        std::uint64_t* const inside;
        std::array<float*, kMaxBlockCubes + 1> value{};  // null while the slice is not taken
        std::array<std::int32_t, kMaxBlockCubes + 1> slot_of{}, free_slot{};
        std::int32_t free_count;
        std::uint32_t live = 0, lowest_live;

        RIVULET_INLINE explicit SliceCaches(BlockSweep& sweep)
            : b(sweep),
              computed(b.s.slice_rows.data()),
              inside(computed + std::size_t(b.n1) * b.n1 * W),
              free_count(static_cast<std::int32_t>(b.n1)),
              lowest_live(b.n1) {
            for (std::uint32_t t = 0; t < b.n1; ++t) free_slot[t] = std::int32_t(t);
        }
        RIVULET_INLINE const std::uint64_t* computed_rows(std::uint32_t t) const {
            return computed + std::size_t(t) * b.n1 * W;
        }
        RIVULET_INLINE const std::uint64_t* inside_rows(std::uint32_t t) const {
            return inside + std::size_t(t) * b.n1 * W;
        }
        RIVULET_INLINE void take(std::uint32_t t) {
            if (value[t] != nullptr) return;
            const std::int32_t slot = free_slot[std::size_t(--free_count)];
            slot_of[t] = slot;
            value[t] = b.s.slices.data() + std::size_t(slot) * b.n1 * b.n1;
            std::fill(computed + std::size_t(t) * b.n1 * W, computed + std::size_t(t + 1) * b.n1 * W,
                      std::uint64_t(0));
            std::fill(inside + std::size_t(t) * b.n1 * W, inside + std::size_t(t + 1) * b.n1 * W,
                      std::uint64_t(0));
            ++b.st.slice_fills;
            b.st.peak_slices = std::max(b.st.peak_slices, ++live);
            lowest_live = std::min(lowest_live, t);
        }
        RIVULET_INLINE void release_below(std::uint32_t k) {
            for (; lowest_live < k; ++lowest_live)
                if (value[lowest_live] != nullptr) {
                    free_slot[std::size_t(free_count++)] = slot_of[lowest_live];
                    value[lowest_live] = nullptr;
                    --live;
                }
        }
        // F at column (i, r) for slices [from, from + RunLanes - 1] (up to the top slice): one pass over the
        // column's entries, so the slabs above in this column mostly find their corners done (a pass costs
        // more for its lookup than for its entries). Recomputing a known corner gives the same bits.
        RIVULET_INLINE void evaluate(std::uint32_t i, std::uint32_t r, std::uint32_t from) {
            const std::uint32_t to = std::min(from + RunLanes - 1, b.n);
            float run[RunLanes];
            cache_column<RunLanes>(b.cache, b.n, i, r, static_cast<std::int32_t>(from),
                                   static_cast<std::int32_t>(to), b.column_z.data() + from, b.f, run);
            const std::size_t word = r * W + i / 64;
            const std::uint64_t bit = std::uint64_t(1) << (i % 64);
            for (std::uint32_t t = from; t <= to; ++t) {
                const float v = run[t - from];
                value[t][r * b.n1 + i] = v;
                computed[std::size_t(t) * b.n1 * W + word] |= bit;
                inside[std::size_t(t) * b.n1 * W + word] |= v >= b.iso ? bit : 0;
            }
        }
    };

    // Floods slab k: every round takes the queued cubes, computes their missing corners and queues the
    // neighbours across the faces they share with the surface (the slabs above and below too). The cubes
    // it took are added to `visit`, their rows to [visit_lo, visit_hi].
    RIVULET_INLINE void flood_slab(std::uint32_t k, SliceCaches& slices, std::uint64_t* frontier,
                                   std::uint64_t* visit, std::int32_t& visit_lo, std::int32_t& visit_hi) {
        const std::uint64_t* const comp_lo = slices.computed_rows(k);
        const std::uint64_t* const comp_hi = slices.computed_rows(k + 1);
        const std::uint64_t* const in_lo = slices.inside_rows(k);
        const std::uint64_t* const in_hi = slices.inside_rows(k + 1);
        const std::int32_t top = static_cast<std::int32_t>(n);
        while (range_lo[k] <= range_hi[k]) {
            const std::int32_t r_lo = range_lo[k], r_hi = range_hi[k];
            range_lo[k] = top, range_hi[k] = -1;
            for (std::int32_t j = r_lo; j <= r_hi; ++j) {
                std::uint64_t* const q = queued + (std::size_t(k) * n + std::size_t(j)) * W;
                const Row cubes = load_row<W>(q);
                store_row<W>(q, Row{});
                store_row<W>(frontier + std::size_t(j) * W, cubes);
                store_row<W>(visit + std::size_t(j) * W, row(visit, std::size_t(j)) | cubes);
            }
            visit_lo = std::min(visit_lo, r_lo), visit_hi = std::max(visit_hi, r_hi);
            for (std::int32_t r = r_lo; r <= r_hi + 1; ++r) {
                Row cubes = r <= r_hi ? row(frontier, std::size_t(r)) : Row{};  // cubes of rows r - 1 and r
                if (r > r_lo) cubes = cubes | row(frontier, std::size_t(r - 1));
                const Row need = cubes | shl1(cubes);
                const Row miss_lo = and_not(need, row(comp_lo, std::size_t(r)));
                const Row miss_hi = and_not(need, row(comp_hi, std::size_t(r)));
                for_each_bit(miss_lo, [&](std::uint32_t i) { slices.evaluate(i, std::uint32_t(r), k); });
                for_each_bit(and_not(miss_hi, miss_lo),
                             [&](std::uint32_t i) { slices.evaluate(i, std::uint32_t(r), k + 1); });
            }
            for (std::int32_t j = r_lo; j <= r_hi; ++j) {
                const Row cubes = row(frontier, std::size_t(j));
                if (!any(cubes)) continue;
                const auto uj = static_cast<std::uint32_t>(j);
                // Corner rows j and j + 1 of the slab's bottom (a, b) and top (c, d) slices.
                const Row a = row(in_lo, uj), b = row(in_lo, uj + 1), c = row(in_hi, uj),
                          d = row(in_hi, uj + 1);
                const Row x_faces = mixed(a, b, c, d);  // bit i: the face at corner column i
                queue_row(k, uj, shr1(cubes & x_faces) | (shl1(cubes & shr1(x_faces)) & cube_row));
                if (uj > 0) queue_row(k, uj - 1, cubes & mixed(a, shr1(a), c, shr1(c)));
                if (uj + 1 < n) queue_row(k, uj + 1, cubes & mixed(b, shr1(b), d, shr1(d)));
                if (k > 0) queue_row(k - 1, uj, cubes & mixed(a, shr1(a), b, shr1(b)));
                if (k + 1 < n) queue_row(k + 1, uj, cubes & mixed(c, shr1(c), d, shr1(d)));
            }
        }
    }

    // ---- vertices: one per crossed edge, created once per block (slab_mesh.h) ----
    // The slab mesher's view of this block, with the edge table cleared; `edge_offset` (12 entries) is
    // filled with the cube-relative edge slots it points to.
    RIVULET_INLINE SlabMesh slab_mesh(std::uint32_t* edge_offset) const {
        const MarchingTables& mt = marching_tables();
        std::uint64_t* const made = s.edge_rows.data();  // slice t, axis a, row r: ((t * 3 + a) * n1 + r) * W
        std::fill(made, made + 3 * std::size_t(n1) * n1 * W, std::uint64_t(0));
        for (std::uint32_t e = 0; e < 12; ++e) {
            const std::uint32_t lc = mt.edge_corner[e][0];
            edge_offset[e] =
                (((lc >> 2) & 1u) * n1 * n1 + ((lc >> 1) & 1u) * n1 + (lc & 1u)) * 3 + mt.edge_axis[e];
        }
        const BlockMeshOut& out = block.out;
        SlabMesh mesh;
        mesh.n = n, mesh.i0 = i0, mesh.j0 = j0, mesh.k0 = k0;
        mesh.last[0] = block.bi + 1 == g.bx, mesh.last[1] = block.bj + 1 == g.by,
        mesh.last[2] = block.bk + 1 == g.bz;
        mesh.voxel = g.voxel, mesh.iso = iso;
        mesh.plane_x = plane_x.data(), mesh.plane_y = plane_y.data(), mesh.plane_z = column_z.data();
        mesh.made = made, mesh.edges = s.edges.data(), mesh.edge_offset = edge_offset;
        mesh.out = out;
        mesh.max_vertices = static_cast<std::uint32_t>(
            std::min({out.positions.size() / 4, out.border.size(), out.foreign.size()}));
        mesh.max_triangles = static_cast<std::uint32_t>(out.triangles.size() / 3);
        return mesh;
    }
};

// The sweep for the row width the block edge needs (one word a row up to 63 cubes).
template <int RunLanes, class Cache>
RIVULET_INLINE BlockSweepStats march_block_rows(const BlockSweepContext& block, const Cache& cache) {
    switch (row_words(block.grid->n)) {
        case 1:
            return BlockSweep<1, RunLanes, Cache>(block, cache).run();
        case 2:
            return BlockSweep<2, RunLanes, Cache>(block, cache).run();
        default:
            return BlockSweep<3, RunLanes, Cache>(block, cache).run();
    }
}

template <class Cache>
BlockSweepStats baseline_build(const BlockSweepContext& block, const Cache& cache) {
    return march_block_rows<4>(block, cache);
}

// flatten: the body's lambdas and the column kernel are inlined here, so they are built for AVX2 too.
template <class Cache>
[[gnu::flatten]] RIVULET_AVX2 BlockSweepStats avx2_build(const BlockSweepContext& block, const Cache& cache) {
    return march_block_rows<8>(block, cache);
}

template <class Cache>
BlockSweepStats dispatch(const BlockSweepContext& block, const Cache& cache) {
    if (cpu_has_avx2()) return avx2_build(block, cache);
    return baseline_build(block, cache);
}

}  // namespace

BlockSweepStats march_block_baseline(const BlockSweepContext& block, const LookupCacheView& cache) {
    return baseline_build(block, cache);
}

BlockSweepStats march_block_baseline(const BlockSweepContext& block, const AnisoLookupCacheView& cache) {
    return baseline_build(block, cache);
}

BlockSweepStats march_block(const BlockSweepContext& block, const LookupCacheView& cache) {
    return dispatch(block, cache);
}

BlockSweepStats march_block(const BlockSweepContext& block, const AnisoLookupCacheView& cache) {
    return dispatch(block, cache);
}

}  // namespace rivulet
