#pragma once
// Particles hashed into cubic cells (a counting sort over a power-of-two table), for fixed-radius
// neighbour queries that run once a frame or less (the spacing measure, the anisotropic kernels' shapes):
// bucket b holds order[heads[b] .. heads[b + 1]), a particle's 27 cells are searched, and a bucket two
// of them share is visited once. Everything is in index order, so a sum over neighbours has the same
// order, and bits, whoever runs it.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "jobs/particle_spans.h"
#include "jobs/vector_lanes.h"

namespace rivulet {

struct CellHash {
    float ox = 0, oy = 0, oz = 0, inv = 1;  // origin and 1 / cell edge
    std::uint32_t mask = 0;                 // table size - 1
    std::span<const std::uint32_t> heads;   // table + 1
    std::span<const std::uint32_t> order;   // one per particle
    // Optional: the coordinates in bucket order (sorted[e] is that of particle order[e]), so a search
    // reads its candidates in sequence instead of gathering them from all over the arrays.
    std::span<const float> sx, sy, sz;

    std::int32_t cell(float v, float o) const { return static_cast<std::int32_t>(std::floor((v - o) * inv)); }
    std::uint32_t key(std::int32_t i, std::int32_t j, std::int32_t k) const {
        return (std::uint32_t(i) * 73856093u ^ std::uint32_t(j) * 19349663u ^ std::uint32_t(k) * 83492791u) &
               mask;
    }
    std::uint32_t of(float x, float y, float z) const { return key(cell(x, ox), cell(y, oy), cell(z, oz)); }
};

// Power-of-two table size for n particles (at least 2 n).
inline std::size_t cell_hash_table_size(std::size_t particles) {
    return std::bit_ceil(std::max<std::size_t>(64, 2 * particles));
}

// Hashes `p` into cells of edge `cell` from `origin`; `heads` needs cell_hash_table_size(n) + 1 slots and
// `order` n. Requires every |coordinate - origin| / cell below 2^30 (the callers bound the data's extent).
inline CellHash build_cell_hash(ConstPositions p, const float origin[3], float cell,
                                std::span<std::uint32_t> heads, std::span<std::uint32_t> order) {
    const std::size_t n = p.size(), table = cell_hash_table_size(n);
    CellHash h;
    h.ox = origin[0], h.oy = origin[1], h.oz = origin[2], h.inv = 1.0f / cell;
    h.mask = static_cast<std::uint32_t>(table - 1);
    h.heads = heads.first(table + 1), h.order = order.first(n);
    std::fill(heads.begin(), heads.begin() + std::ptrdiff_t(table) + 1, 0u);
    for (std::size_t i = 0; i < n; ++i) ++heads[h.of(p.x[i], p.y[i], p.z[i]) + 1];
    for (std::size_t b = 0; b < table; ++b) heads[b + 1] += heads[b];
    // Scatter with the heads as cursors, then shift them back.
    for (std::size_t i = 0; i < n; ++i) order[heads[h.of(p.x[i], p.y[i], p.z[i])]++] = std::uint32_t(i);
    for (std::size_t b = table; b > 0; --b) heads[b] = heads[b - 1];
    heads[0] = 0;
    return h;
}

// Copies the coordinates into bucket order (each span n) and points `h` at them.
inline void sort_cell_hash_positions(CellHash& h, ConstPositions p, std::span<float> x, std::span<float> y,
                                     std::span<float> z) {
    for (std::size_t e = 0; e < h.order.size(); ++e) {
        const std::uint32_t j = h.order[e];
        x[e] = p.x[j], y[e] = p.y[j], z[e] = p.z[j];
    }
    h.sx = x.first(h.order.size()), h.sy = y.first(h.order.size()), h.sz = z.first(h.order.size());
}

// True the first time bucket b comes up among a query's 27 cells (records it). A bit per b mod 64 rules
// out most repeats without a search: collisions are rare, the search over `seen` is the exception.
inline bool first_visit(std::uint32_t b, std::uint32_t* seen, std::uint32_t& seen_n, std::uint64_t& bits) {
    const std::uint64_t bit = std::uint64_t{1} << (b & 63u);
    if ((bits & bit) != 0 && std::find(seen, seen + seen_n, b) != seen + seen_n) return false;
    bits |= bit;
    seen[seen_n++] = b;
    return true;
}

// Calls run(begin, end) for each bucket of the 27 cells around cell (ci, cj, ck) that keep(di, dj, dk)
// accepts, each bucket once: its entries [begin, end) of `order` (and of the sorted coordinates), at most
// `max_scan` entries in all (more means a pile far denser than the cell, e.g. coincident particles,
// which would otherwise make the caller quadratic). A bucket is marked visited only when it is run, so
// one that a rejected cell shares with an accepted one is still run for the accepted one.
template <class Keep, class Run>
void for_each_kept_bucket(const CellHash& h, std::int32_t ci, std::int32_t cj, std::int32_t ck,
                          std::uint32_t max_scan, Keep&& keep, Run&& run) {
    std::uint32_t seen[27], seen_n = 0, budget = max_scan;
    std::uint64_t seen_bits = 0;
    for (std::int32_t dk = -1; dk <= 1; ++dk)
        for (std::int32_t dj = -1; dj <= 1; ++dj)
            for (std::int32_t di = -1; di <= 1; ++di) {
                if (!keep(di, dj, dk)) continue;
                const std::uint32_t b = h.key(ci + di, cj + dj, ck + dk);
                if (!first_visit(b, seen, seen_n, seen_bits)) continue;  // a shared bucket
                const std::uint32_t begin = h.heads[b], end = std::min(h.heads[b + 1], begin + budget);
                budget -= end - begin;
                run(begin, end);
            }
}

// Every bucket of the 27 cells around (x, y, z).
template <class Run>
void for_each_bucket_near(const CellHash& h, float x, float y, float z, std::uint32_t max_scan, Run&& run) {
    for_each_kept_bucket(
        h, h.cell(x, h.ox), h.cell(y, h.oy), h.cell(z, h.oz), max_scan,
        [](std::int32_t, std::int32_t, std::int32_t) { return true; }, run);
}

// for_each_bucket_near without the cells that lie wholly farther than `radius` from (x, y, z) (with cells
// of edge `radius`, about a quarter of the 27: corners and edges).
template <class Run>
void for_each_bucket_within(const CellHash& h, float x, float y, float z, float radius,
                            std::uint32_t max_scan, Run&& run) {
    const std::int32_t ci = h.cell(x, h.ox), cj = h.cell(y, h.oy), ck = h.cell(z, h.oz);
    // Per axis, the squared distance in cell edges to the cell below, this one and the one above.
    const float ux = (x - h.ox) * h.inv - float(ci), uy = (y - h.oy) * h.inv - float(cj),
                uz = (z - h.oz) * h.inv - float(ck);
    const float gap[3][3] = {{ux * ux, 0.0f, (1 - ux) * (1 - ux)},
                             {uy * uy, 0.0f, (1 - uy) * (1 - uy)},
                             {uz * uz, 0.0f, (1 - uz) * (1 - uz)}};
    const float reach = radius * h.inv, reach2 = reach * reach * 1.0001f;  // rounding never culls a neighbour
    for_each_kept_bucket(
        h, ci, cj, ck, max_scan,
        [&](std::int32_t di, std::int32_t dj, std::int32_t dk) {
            return !(gap[0][di + 1] + gap[1][dj + 1] + gap[2][dk + 1] > reach2);
        },
        run);
}

// Calls visit(j, dx, dy, dz) with d = p[j] - p[i] for the particles in the buckets of the 27 cells around
// particle i (i included), at most `max_scan` of them.
template <class Visit>
void for_each_near(ConstPositions p, const CellHash& h, std::size_t i, std::uint32_t max_scan,
                   Visit&& visit) {
    const float x = p.x[i], y = p.y[i], z = p.z[i];
    for_each_bucket_near(h, x, y, z, max_scan, [&](std::uint32_t begin, std::uint32_t end) {
        if (!h.sx.empty())
            for (std::uint32_t e = begin; e < end; ++e)
                visit(h.order[e], h.sx[e] - x, h.sy[e] - y, h.sz[e] - z);
        else
            for (std::uint32_t e = begin; e < end; ++e) {
                const std::uint32_t j = h.order[e];
                visit(j, p.x[j] - x, p.y[j] - y, p.z[j] - z);
            }
    });
}

// Calls visit(j, dx, dy, dz, r2) for the particles of for_each_near with r2 = |d|^2 < r2_max, in the
// same order; needs the sorted coordinates (sort_cell_hash_positions). Four candidates are tested at a
// time (each lane the scalar expression, so the same r2 bits), only the hits visited.
template <class Visit>
void for_each_within(const CellHash& h, float x, float y, float z, float r2_max, std::uint32_t max_scan,
                     Visit&& visit) {
    using fv = VectorLanes<4>::f;
    using iv = VectorLanes<4>::i;
    const fv vx = fv{} + x, vy = fv{} + y, vz = fv{} + z, vr = fv{} + r2_max;
    for_each_bucket_near(h, x, y, z, max_scan, [&](std::uint32_t begin, std::uint32_t end) {
        std::uint32_t e = begin;
        for (; e + 4 <= end; e += 4) {
            fv px, py, pz;
            std::memcpy(&px, h.sx.data() + e, sizeof px);
            std::memcpy(&py, h.sy.data() + e, sizeof py);
            std::memcpy(&pz, h.sz.data() + e, sizeof pz);
            const fv dx = px - vx, dy = py - vy, dz = pz - vz;
            const fv r2 = dx * dx + dy * dy + dz * dz;
            const iv hit = r2 < vr;
            for (int l = 0; l < 4; ++l)
                if (hit[l]) visit(h.order[e + std::uint32_t(l)], dx[l], dy[l], dz[l], r2[l]);
        }
        for (; e < end; ++e) {
            const float dx = h.sx[e] - x, dy = h.sy[e] - y, dz = h.sz[e] - z;
            const float r2 = dx * dx + dy * dy + dz * dz;
            if (r2 < r2_max) visit(h.order[e], dx, dy, dz, r2);
        }
    });
}

}  // namespace rivulet
