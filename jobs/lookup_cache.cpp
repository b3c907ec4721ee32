#include "jobs/lookup_cache.h"

#include <algorithm>
#include <array>

#include "jobs/simd4.h"

namespace rivulet {
namespace {

constexpr std::uint16_t kEmptyRow = 0x00ff;  // i_lo = 255 > i_hi = 0
constexpr std::uint32_t kWindow = 64;        // columns tested per window of row tests (16 x 4 lanes)

// Counting sort of the block's particles by mid_z into s.order (stable: ascending index within a slab);
// mid_z computed once per particle, into s.mids.
void sort_by_mid_z(const SliceGrid& g, std::int32_t k0, std::span<const float> z, std::uint32_t np,
                   const LookupScratch& s) {
    const std::int32_t mid_base = -g.reach - 2;
    const std::uint32_t slots = static_cast<std::uint32_t>(s.counts.size());
    auto sort_slot = [&](std::int32_t mid) {
        return static_cast<std::uint32_t>(
            std::clamp<std::int32_t>(mid - mid_base, 0, std::int32_t(slots) - 1));
    };
    std::fill(s.counts.begin(), s.counts.end(), 0u);
    for (std::uint32_t q = 0; q < np; ++q) {
        s.mids[q] = SliceGrid::cell(z[q], g.oz, g.inv_voxel) - k0;
        ++s.counts[sort_slot(s.mids[q])];
    }
    std::uint32_t run = 0;
    for (auto& c : s.counts) {
        const std::uint32_t k = c;
        c = run;
        run += k;
    }
    for (std::uint32_t q = 0; q < np; ++q) s.order[s.counts[sort_slot(s.mids[q])]++] = q;
}

// Entries per column from the row runs' +1 / -1 marks (`diff`, rows of `stride`), then each column's
// start (into `ends`, the cursors of pass 2); returns the total.
std::uint32_t column_starts(const SliceGrid& g, const std::uint32_t* diff, std::uint32_t stride,
                            std::uint32_t* ends) {
    for (std::uint32_t j = 0; j <= g.n; ++j) {
        std::uint32_t sum = 0;
        for (std::uint32_t i = 0; i <= g.n; ++i) ends[j * (g.n + 1) + i] = sum += diff[j * stride + i];
    }
    std::uint32_t total = 0;
    for (std::uint32_t c = 0; c < (g.n + 1) * (g.n + 1); ++c) {
        const std::uint32_t k = ends[c];
        ends[c] = total;
        total += k;
    }
    return total;
}

// Pass 2 appends the particles sorted by mid_z, so group by group; where a group begins, the cursors are
// where its entries start in every column.
struct GroupStarts {
    std::uint32_t* offsets;
    const std::uint32_t* cursors;
    std::uint32_t cols;
    std::uint32_t started = 0;
    void up_to(std::uint32_t group) {
        for (; started <= group; ++started)
            std::copy(cursors, cursors + cols, offsets + std::size_t(started) * cols);
    }
};

// Pass 2: appends every listed particle (sorted by mid_z) to the columns of its row runs, as
// make(q)(dx, dy) with d = column axis - centre; returns nothing, the counts are pass 1's. make(q) reads
// the particle's values once: inside the row loop every entry's store could alias them, and the
// compiler reloaded them per entry.
template <class Entry, class Make>
void append_entries(const SliceGrid& g, std::int32_t n, ConstPositions p, const LookupScratch& s,
                    std::uint32_t row_slots, const float* axis_x, const float* axis_y, std::uint32_t* ends,
                    std::span<std::uint32_t> offsets, std::span<Entry> entries, Make&& make) {
    const std::uint32_t row = g.n + 1, cols = row * row, groups = lookup_groups(g), row_runs = row_slots - 1;
    const std::int32_t reach = g.reach;
    Entry* const out = entries.data();
    GroupStarts start_groups{offsets.data(), ends, cols};
    for (std::uint32_t o = 0; o < static_cast<std::uint32_t>(p.size()); ++o) {
        const std::uint32_t q = s.order[o];
        const std::int32_t mid = s.mids[q];
        if (mid + reach + 1 < 0 || mid - reach > n) continue;  // reaches no slice of the block
        const std::uint16_t* rows = s.rows.data() + std::size_t(o) * row_slots;
        const std::int32_t by = static_cast<std::int16_t>(rows[row_runs]);
        start_groups.up_to(lookup_group(mid, reach));
        const float px = p.x[q], py = p.y[q];
        const auto entry = make(q);
        for (std::uint32_t r = 0; r < row_runs; ++r) {
            const std::int32_t a = rows[r] & 0xff, b = rows[r] >> 8;
            if (a > b) continue;
            const std::int32_t j = by + std::int32_t(r);
            const float dy = axis_y[j] - py;
            std::uint32_t* cursor = ends + std::uint32_t(j) * row;
            for (std::int32_t i = a; i <= b; ++i) out[cursor[i]++] = entry(axis_x[i] - px, dy);
        }
    }
    if (groups > 0) start_groups.up_to(groups - 1);  // groups after the last particle's start at the ends
}

}  // namespace

std::uint32_t build_lookup_cache(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj, std::uint32_t bk,
                                 ConstPositions p, const LookupScratch& s, std::span<std::uint32_t> offsets,
                                 std::span<ColumnEntry> entries) {
    const std::int32_t n = static_cast<std::int32_t>(g.n);
    const std::int32_t i0 = static_cast<std::int32_t>(bi) * n, j0 = static_cast<std::int32_t>(bj) * n,
                       k0 = static_cast<std::int32_t>(bk) * n;
    const std::uint32_t cols = (g.n + 1) * (g.n + 1);
    const std::uint32_t np = static_cast<std::uint32_t>(p.size());
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    const std::uint32_t row_slots = static_cast<std::uint32_t>(lookup_row_slots(g));
    const std::uint32_t row_runs = row_slots - 1;  // then the reach box's first row
    const std::uint32_t groups = lookup_groups(g);
    std::uint32_t* const ends = offsets.data() + std::size_t(groups) * cols;  // counts, cursors, then ends

    // Column axes, computed once as every corner computes them (SliceGrid::cx / cy); x padded for the
    // four-lane row tests (the padding lanes are masked off).
    std::array<float, kMaxBlockCubes + 1 + kWindow> axis_x{};
    std::array<float, kMaxBlockCubes + 1> axis_y{};
    for (std::int32_t i = 0; i <= n; ++i)
        axis_x[std::size_t(i)] = g.cx(i0 + i), axis_y[std::size_t(i)] = g.cy(j0 + i);

    sort_by_mid_z(g, k0, p.z, np, s);

    // Pass 1: per particle (in sorted order) and row of its reach box, the run of columns within R_c
    // (row_runs rows from the box's first row, which follows them in `rows`; a row is one interval:
    // dx * dx grows with |dx|); count the entries per column, as +1 where a row's run starts and -1 after
    // it ends (summed along the row below). Pass 2 places them without repeating the distance tests.
    const std::uint32_t diff_stride = g.n + 2;   // a row's run may end after column n
    std::uint32_t* const diff = offsets.data();  // rows of group starts are written only in pass 2
    std::fill(diff, diff + std::size_t(g.n + 1) * diff_stride, 0u);
    auto cz_listed = [&](std::int32_t cz) { return cz + g.reach + 1 >= 0 && cz - g.reach <= n; };
    std::array<simd::F4, (kMaxBlockCubes + 1 + 3) / 4> dx2;
    const simd::F4 rc2v = simd::splat(f.rc2);
    for (std::uint32_t o = 0; o < np; ++o) {
        const std::uint32_t q = s.order[o];
        const float x = p.x[q], y = p.y[q];
        std::uint16_t* rows = s.rows.data() + std::size_t(o) * row_slots;
        std::fill(rows, rows + row_runs, kEmptyRow);
        if (!cz_listed(s.mids[q])) continue;  // reaches no slice of the block
        const std::int32_t cx = SliceGrid::cell(x, g.ox, g.inv_voxel) - i0,
                           by = SliceGrid::cell(y, g.oy, g.inv_voxel) - j0 - g.reach;
        rows[row_runs] = static_cast<std::uint16_t>(by);
        const std::int32_t ilo = std::max(0, cx - g.reach), ihi = std::min(n, cx + g.reach + 1);
        const std::int32_t jlo = std::max(0, by), jhi = std::min(n, by + 2 * g.reach + 1);
        if (ilo > ihi) continue;
        // dx * dx of the candidate columns, four at a time: a row's test is then one add and one compare
        // per four columns, with the same float expression as the corner distance minus its z term
        // ((a - x)^2 is (x - a)^2 exactly).
        const auto width = static_cast<std::uint32_t>(ihi - ilo + 1);
        const std::uint32_t quads = (width + 3) / 4;
        for (std::uint32_t t = 0; t < quads; ++t) {
            const simd::F4 dx = simd::load(axis_x.data() + ilo + 4 * t) - simd::splat(x);
            dx2[t] = dx * dx;
        }
        for (std::int32_t j = jlo; j <= jhi; ++j) {
            const float dy = y - axis_y[std::size_t(j)];
            const float dy2 = dy * dy;
            if (!(dy2 < f.rc2)) continue;  // then no dx passes either
            // The columns within R_c form one run (dx * dx grows with |dx|): its first and last set bit.
            const simd::F4 dy2v = simd::splat(dy2);
            std::int32_t a = -1, b = -1;
            for (std::uint32_t w = 0; w < quads; w += kWindow / 4) {
                std::uint64_t mask = 0;
                for (std::uint32_t t = w; t < std::min(quads, w + kWindow / 4); ++t)
                    mask |= std::uint64_t(simd::less_mask(dx2[t] + dy2v, rc2v)) << (4 * (t - w));
                const std::uint32_t left = width - 4 * w;  // columns from this window on
                if (left < 64) mask &= (std::uint64_t(1) << left) - 1;
                if (mask == 0) continue;
                const std::int32_t at = ilo + std::int32_t(4 * w);
                if (a < 0) a = at + __builtin_ctzll(mask);
                b = at + 63 - __builtin_clzll(mask);
            }
            if (a < 0) continue;
            rows[j - by] = static_cast<std::uint16_t>(a | b << 8);
            std::uint32_t* const row_diff = diff + std::uint32_t(j) * diff_stride;
            ++row_diff[a], --row_diff[b + 1];
        }
    }
    const std::uint32_t total = column_starts(g, diff, diff_stride, ends);
    if (total > entries.size()) return total;
    // (a - x)^2 is (x - a)^2 exactly: the entries are those of the corner distance minus its z term.
    append_entries(g, n, p, s, row_slots, axis_x.data(), axis_y.data(), ends, offsets, entries,
                   [&](std::uint32_t q) {
                       return [z = p.z[q]](float dx, float dy) { return ColumnEntry{dx * dx + dy * dy, z}; };
                   });
    return total;
}

std::uint32_t build_aniso_lookup_cache(const SliceGrid& g, std::uint32_t bi, std::uint32_t bj,
                                       std::uint32_t bk, ConstPositions p, std::span<const std::uint32_t> ids,
                                       ConstKernelShapes shape, const LookupScratch& s,
                                       std::span<std::uint32_t> offsets, std::span<AnisoEntry> entries) {
    const std::int32_t n = static_cast<std::int32_t>(g.n);
    const std::int32_t i0 = static_cast<std::int32_t>(bi) * n, j0 = static_cast<std::int32_t>(bj) * n,
                       k0 = static_cast<std::int32_t>(bk) * n;
    const std::uint32_t cols = (g.n + 1) * (g.n + 1);
    const std::uint32_t np = static_cast<std::uint32_t>(p.size());
    const float rc2 = SliceKernel::from_rc(g.rc).rc2;
    const std::uint32_t row_slots = static_cast<std::uint32_t>(lookup_row_slots(g));
    const std::uint32_t row_runs = row_slots - 1;
    const std::uint32_t groups = lookup_groups(g);
    std::uint32_t* const ends = offsets.data() + std::size_t(groups) * cols;

    std::array<float, kMaxBlockCubes + 1> axis_x{}, axis_y{};
    for (std::int32_t i = 0; i <= n; ++i)
        axis_x[std::size_t(i)] = g.cx(i0 + i), axis_y[std::size_t(i)] = g.cy(j0 + i);
    sort_by_mid_z(g, k0, p.z, np, s);

    // The metric's distance from a particle's centre to a column, in float, the expression the test
    // oracle repeats (a column on a block border gets the same bits from both blocks); pass 1 finds the
    // runs from the roots in double instead, with a column of margin.
    auto column_a = [&](std::uint32_t id, float dx, float dy) {
        return (shape.sxx[id] * dx + 2.0f * shape.sxy[id] * dy) * dx + shape.syy[id] * (dy * dy);
    };
    // Pass 1: per particle and row of its reach box, the run of columns its ellipsoid meets, from the
    // roots of a(dx, dy) = R_c^2 in dx and a column of margin either side for rounding (a column of the
    // run outside the ellipsoid adds exactly +0, so the margin changes no corner's value).
    const std::uint32_t diff_stride = g.n + 2;
    std::uint32_t* const diff = offsets.data();
    std::fill(diff, diff + std::size_t(g.n + 1) * diff_stride, 0u);
    auto cz_listed = [&](std::int32_t cz) { return cz + g.reach + 1 >= 0 && cz - g.reach <= n; };
    for (std::uint32_t o = 0; o < np; ++o) {
        const std::uint32_t q = s.order[o], id = ids[q];
        const float x = p.x[q], y = p.y[q];
        std::uint16_t* rows = s.rows.data() + std::size_t(o) * row_slots;
        std::fill(rows, rows + row_runs, kEmptyRow);
        if (!cz_listed(s.mids[q])) continue;
        const std::int32_t cx = SliceGrid::cell(x, g.ox, g.inv_voxel) - i0,
                           by = SliceGrid::cell(y, g.oy, g.inv_voxel) - j0 - g.reach;
        rows[row_runs] = static_cast<std::uint16_t>(by);
        const std::int32_t ilo = std::max(0, cx - g.reach), ihi = std::min(n, cx + g.reach + 1);
        const std::int32_t jlo = std::max(0, by), jhi = std::min(n, by + 2 * g.reach + 1);
        if (ilo > ihi) continue;
        const double sxx = shape.sxx[id], sxy = shape.sxy[id], syy = shape.syy[id];
        for (std::int32_t j = jlo; j <= jhi; ++j) {
            const double dy = double(axis_y[std::size_t(j)]) - double(y);
            const double disc = (sxy * dy) * (sxy * dy) - sxx * (syy * dy * dy - double(rc2));
            // The row misses the ellipsoid: its closest column has a > R_c^2 by more than float rounding.
            if (!(disc >= -1e-5 * sxx * double(rc2))) continue;
            const double root = std::sqrt(std::max(disc, 0.0));
            const double lo = (-sxy * dy - root) / sxx, hi = (-sxy * dy + root) / sxx;  // dx range
            const double first = std::floor((double(x) + lo - double(axis_x[0])) * double(g.inv_voxel)) - 1;
            const double last = std::ceil((double(x) + hi - double(axis_x[0])) * double(g.inv_voxel)) + 1;
            const std::int32_t a = static_cast<std::int32_t>(std::max<double>(ilo, first)),
                               b = static_cast<std::int32_t>(std::min<double>(ihi, last));
            if (a > b) continue;
            rows[j - by] = static_cast<std::uint16_t>(a | b << 8);
            std::uint32_t* const row_diff = diff + std::uint32_t(j) * diff_stride;
            ++row_diff[a], --row_diff[b + 1];
        }
    }
    const std::uint32_t total = column_starts(g, diff, diff_stride, ends);
    if (total > entries.size()) return total;
    append_entries(
        g, n, p, s, row_slots, axis_x.data(), axis_y.data(), ends, offsets, entries, [&](std::uint32_t q) {
            return [&, q, id = ids[q]](float dx, float dy) {
                return AnisoEntry{column_a(id, dx, dy), p.z[q] + shape.gx[id] * dx + shape.gy[id] * dy,
                                  shape.c[id], shape.amp[id]};
            };
        });
    return total;
}

}  // namespace rivulet
