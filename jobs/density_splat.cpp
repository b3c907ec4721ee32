#include "jobs/density_splat.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/vector_lanes.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace rivulet {

ParticleBounds particle_bounds(ConstPositions p) {
    ParticleBounds b;
    const std::span<const float> axes[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
        float lo = axes[a].empty() ? 0.0f : axes[a][0], hi = lo;
        bool finite = true;
        for (const float v : axes[a]) {
            lo = std::min(lo, v), hi = std::max(hi, v);
            finite &= std::isfinite(v);
        }
        b.lo[a] = lo, b.hi[a] = hi;
        b.finite &= finite && std::isfinite(lo) && std::isfinite(hi);
    }
    return b;
}

ParticleBounds merge_bounds(const ParticleBounds& a, const ParticleBounds& b) {
    ParticleBounds m;
    for (int i = 0; i < 3; ++i) m.lo[i] = std::min(a.lo[i], b.lo[i]), m.hi[i] = std::max(a.hi[i], b.hi[i]);
    m.finite = a.finite && b.finite;
    return m;
}

DensityGrid plan_density_grid(const ParticleBounds& bounds, const DensityGridParams& params) {
    if (!bounds.finite)
        throw std::invalid_argument("density volume: some particle positions are NaN or infinite");
    if (!(params.h > 0) || !std::isfinite(params.h))
        throw std::invalid_argument("density volume: the kernel radius must be positive and finite");
    if (params.max_dim < 2 * kBrickCells || params.max_dim % kBrickCells != 0)
        throw std::invalid_argument("--max-dim must be a multiple of 8 and at least 16, got " +
                                    std::to_string(params.max_dim));
    const double h = params.h;
    double lo[3], extent[3], longest = 0;
    for (int a = 0; a < 3; ++a) {
        lo[a] = double(bounds.lo[a]) - h;
        extent[a] = double(bounds.hi[a]) + h - lo[a];
        longest = std::max(longest, extent[a]);
    }
    // One cell of slack for snapping the origin to whole voxels.
    const double max_cells = double(params.max_dim) - 1.0;
    double voxel = params.voxel;
    if (voxel > 0) {
        static const char* const kAxis[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a)
            if (const double cells = std::ceil(extent[a] / voxel); !(cells <= max_cells))
                throw std::invalid_argument("--voxel " + std::to_string(voxel) + " would make " +
                                            std::to_string(cells + 1.0) + " cells along " + kAxis[a] +
                                            ", more than --max-dim " + std::to_string(params.max_dim));
    } else {
        voxel = std::max(h / 4.0, longest / (max_cells - 1.0));
    }
    if (!std::isfinite(voxel) || !(voxel > 0))
        throw std::invalid_argument("density volume: the particles' extent is too large for a grid");
    DensityGrid g;
    g.voxel = static_cast<float>(voxel);
    g.h = params.h;
    g.volume = params.volume;
    std::uint32_t bricks[3];
    float origin[3];
    for (int a = 0; a < 3; ++a) {
        const double o = std::floor(lo[a] / voxel) * voxel;
        origin[a] = static_cast<float>(o);
        const double cells = std::ceil((lo[a] + extent[a] - double(origin[a])) / double(g.voxel)) + 1.0;
        const double b = std::max(1.0, std::ceil(cells / kBrickCells));
        bricks[a] = static_cast<std::uint32_t>(std::min<double>(b, params.max_dim / kBrickCells));
    }
    g.ox = origin[0], g.oy = origin[1], g.oz = origin[2];
    g.bx = bricks[0], g.by = bricks[1], g.bz = bricks[2];
    return g;
}

namespace {

std::uint32_t brick_along(float p, float o, float inv_brick, std::uint32_t n) {
    const float t = (p - o) * inv_brick;
    if (!(t > 0)) return 0;
    return std::min(static_cast<std::uint32_t>(t), n - 1);
}

// Bricks [first[i], last[i]] along one axis whose samples lie within h_voxels of coordinate p[i],
// conservatively (a sample of margin each side), for n <= kRangeBlock coordinates. Brick c holds samples
// [8c, 8c + 8]. Branch-free over arrays, so the compiler does it in vector lanes.
constexpr std::size_t kRangeBlock = 64;
inline void brick_ranges(const float* p, std::size_t n, float o, float inv_voxel, float h_voxels,
                         std::uint32_t bricks, std::uint32_t* first, std::uint32_t* last) {
    const float top = float(bricks * kBrickCells);
    const std::int32_t last_brick = std::int32_t(bricks) - 1;
    for (std::size_t i = 0; i < n; ++i) {
        const float t = (p[i] - o) * inv_voxel;
        const float a = std::min(std::max(t - h_voxels - 1.0f, 0.0f), top),
                    b = std::min(std::max(t + h_voxels + 1.0f, 0.0f), top);
        const auto lo = static_cast<std::int32_t>(a), hi = static_cast<std::int32_t>(b);
        first[i] = std::uint32_t((std::max(lo, 1) - 1) / std::int32_t(kBrickCells));
        last[i] = std::uint32_t(std::min(hi / std::int32_t(kBrickCells), last_brick));
    }
}

// Local bricks of group G (of n bricks along an axis) that bricks [lo, hi] cover, as bits.
inline std::uint32_t group_bits(std::uint32_t G, std::uint32_t n, std::uint32_t lo, std::uint32_t hi) {
    const std::uint32_t first = G * n;
    std::uint32_t m = (1u << n) - 1;
    if (lo > first) m &= ~0u << (lo - first);
    if (hi < first + n - 1) m &= (2u << (hi - first)) - 1;
    return m;
}

// Per set of a group's rows of bricks (bit c * kGroupBricksY + b), the mask with the first brick of each:
// times the bricks a row reaches along x (fewer than 2^kGroupBricksX), the bricks reached, no carries.
constexpr std::uint32_t kGroupRows = kGroupBricksY * kGroupBricksZ;
static_assert(kGroupRows <= 8, "a table entry per set of a group's rows");
constexpr std::array<GroupBrickMask, 1u << kGroupRows> kRowBases = [] {
    std::array<GroupBrickMask, 1u << kGroupRows> table{};
    for (std::uint32_t rows = 0; rows < table.size(); ++rows)
        for (std::uint32_t r = 0; r < kGroupRows; ++r)
            if (rows >> r & 1u) table[rows] |= GroupBrickMask(1) << (r * kGroupBricksX);
    return table;
}();

// Calls f(i, group, mask) for every particle i of `p` and every group with a brick whose samples lie
// within h of it (conservatively), with the bricks of that group it reaches (GroupBrickMask's bit order).
template <bool kMask, class F>
void for_each_reached_group(const DensityGrid& g, ConstPositions p, F&& f) {
    const float inv_voxel = 1.0f / g.voxel, hv = g.h * inv_voxel;
    const DensityGroups groups = density_groups(g);
    std::uint32_t a0[kRangeBlock], a1[kRangeBlock], b0[kRangeBlock], b1[kRangeBlock], c0[kRangeBlock],
        c1[kRangeBlock];
    for (std::size_t start = 0; start < p.size(); start += kRangeBlock) {
        const std::size_t n = std::min(kRangeBlock, p.size() - start);
        brick_ranges(p.x.data() + start, n, g.ox, inv_voxel, hv, g.bx, a0, a1);
        brick_ranges(p.y.data() + start, n, g.oy, inv_voxel, hv, g.by, b0, b1);
        brick_ranges(p.z.data() + start, n, g.oz, inv_voxel, hv, g.bz, c0, c1);
        for (std::size_t i = 0; i < n; ++i)
            for (std::uint32_t C = c0[i] / kGroupBricksZ; C <= c1[i] / kGroupBricksZ; ++C) {
                const std::uint32_t mc = kMask ? group_bits(C, kGroupBricksZ, c0[i], c1[i]) : 0;
                for (std::uint32_t B = b0[i] / kGroupBricksY; B <= b1[i] / kGroupBricksY; ++B) {
                    // The rows (b, c) of the group it reaches, bit c * kGroupBricksY + b.
                    std::uint32_t rows = 0;
                    if constexpr (kMask) {
                        const std::uint32_t mb = group_bits(B, kGroupBricksY, b0[i], b1[i]);
                        for (std::uint32_t lc = 0; lc < kGroupBricksZ; ++lc)
                            rows |= (mb << (lc * kGroupBricksY)) & (0u - (mc >> lc & 1u));
                    }
                    for (std::uint32_t A = a0[i] / kGroupBricksX; A <= a1[i] / kGroupBricksX; ++A) {
                        GroupBrickMask m = 0;
                        if constexpr (kMask)
                            m = kRowBases[rows] * GroupBrickMask(group_bits(A, kGroupBricksX, a0[i], a1[i]));
                        f(start + i, (C * groups.gy + B) * groups.gx + A, m);
                    }
                }
            }
    }
}

}  // namespace

DensityGroups density_groups(const DensityGrid& grid) {
    return {(grid.bx + kGroupBricksX - 1) / kGroupBricksX, (grid.by + kGroupBricksY - 1) / kGroupBricksY,
            (grid.bz + kGroupBricksZ - 1) / kGroupBricksZ};
}

std::uint32_t density_brick_of(const DensityGrid& grid, float x, float y, float z) {
    const float inv = 1.0f / (grid.voxel * kBrickCells);
    return grid.brick_index(brick_along(x, grid.ox, inv, grid.bx), brick_along(y, grid.oy, inv, grid.by),
                            brick_along(z, grid.oz, inv, grid.bz));
}

std::uint32_t density_max_bricks_per_particle(const DensityGrid& grid) {
    // 2 h + 2 samples of margin span at most this many bricks per axis.
    const auto per_axis =
        static_cast<std::uint32_t>((2.0f * grid.h / grid.voxel + 2.0f) / float(kBrickCells)) + 2;
    return per_axis * per_axis * per_axis;
}

void density_bin_count_chunk(const DensityGrid& grid, ConstPositions p, std::span<std::uint32_t> counts,
                             std::span<GroupBrickMask> masks) {
    for_each_reached_group<true>(grid, p, [&](std::size_t, std::uint32_t g, GroupBrickMask m) {
        ++counts[g];
        masks[g] |= m;
    });
}

void density_bin_scatter_chunk(const DensityGrid& grid, ConstPositions p, std::uint32_t first,
                               std::span<std::uint32_t> cursors, std::span<std::uint32_t> entries) {
    for_each_reached_group<false>(grid, p, [&](std::size_t i, std::uint32_t g, GroupBrickMask) {
        entries[cursors[g]++] = first + static_cast<std::uint32_t>(i);
    });
}

std::uint32_t density_allocate_bricks(const DensityGrid& grid, std::span<const GroupBrickMask> masks,
                                      std::span<std::int32_t> brick_slot, std::span<std::uint32_t> slot_brick,
                                      std::span<std::uint32_t> groups_out, std::uint32_t& group_count) {
    const DensityGroups gs = density_groups(grid);
    std::uint32_t slots = 0;
    for (std::uint32_t c = 0; c < grid.bz; ++c)
        for (std::uint32_t b = 0; b < grid.by; ++b) {
            const std::uint32_t row = ((c / kGroupBricksZ) * gs.gy + b / kGroupBricksY) * gs.gx;
            const std::uint32_t shift =
                ((c % kGroupBricksZ) * kGroupBricksY + b % kGroupBricksY) * kGroupBricksX;
            for (std::uint32_t a = 0; a < grid.bx; ++a) {
                const std::uint32_t brick = grid.brick_index(a, b, c);
                if (!(masks[row + a / kGroupBricksX] >> (shift + a % kGroupBricksX) & 1u)) {
                    brick_slot[brick] = -1;
                    continue;
                }
                if (slots < slot_brick.size()) slot_brick[slots] = brick;
                brick_slot[brick] = static_cast<std::int32_t>(slots++);
            }
        }
    group_count = 0;
    for (std::uint32_t g = 0; g < gs.count(); ++g)
        if (masks[g]) groups_out[group_count++] = g;
    return slots;
}

namespace {

// A group row's samples as lanes: a row of samples [ia, ib] read in L-wide vectors from ia ends by lane
// ib + L - 1, inside the row for L <= 8 (the lanes past the group are summed but never read out).
constexpr std::uint32_t kLanes = (kGroupEdgeX + 7) / 8 * 8 + 8;

// A range test's margin, in samples: far above the rounding of the distances (about 1e-4 samples at
// --max-dim 4096), so every sample whose computed q is positive is visited in every group that holds it
// and the faces groups share get the same sums; far below a sample, so it rarely visits one more.
constexpr float kMargin = 0.05f;

// Sample indices [first, last] within [0, edge] of a group row at most r samples from t (t the
// coordinate in samples from the group's first): floor(t - r) + 1 to floor(t + r), widened by kMargin,
// without a branch. Truncation instead of floor, which is a library call on the x86-64 baseline, where
// the value is known to be non-negative; a + 1 rounding up to a whole number drops only a sample kMargin
// beyond r. False when none.
RIVULET_INLINE bool sample_range(float t, float r, int edge, int& first, int& last) {
    const float a = t - r - kMargin, b = t + r + kMargin;
    first = static_cast<int>(std::clamp(a + 1.0f, 0.0f, float(edge) + 1.0f));
    last = static_cast<int>(std::clamp(b, -1.0f, float(edge)));
    return (b >= 0.0f) & (a <= float(edge)) & (first <= last);
}

// Sample i of a group along an axis lies at origin + voxel * (first + i), as DensityGrid computes it.
struct GroupAxis {
    float origin, voxel;
    std::uint32_t first;
    int edge;  // the group's last sample index along the axis
    float at(int i) const { return origin + voxel * static_cast<float>(first + std::uint32_t(i)); }
};
struct GroupFrame {
    const float* sx;  // kLanes sample x coordinates
    const float* sy;  // kGroupEdgeY + 8 sample y coordinates
    const float* sz;  // kGroupEdgeZ + 8
    float inv_voxel, h_voxels, inv_h2;
    GroupAxis ax, ay, az;
    float mass_over_volume;  // the particles' mass over grid.volume: a particle's weight times its density
};
struct Particle {
    float x, y, z;
    int ia, ja, jb, ka, kb;  // sample ranges it can reach; x: [ia, ia + L vectors)
    float weight;            // V_j / grid.volume (1 unless the particles' volumes are given)
};

// d = max(d, 0) per lane as maxps does it (0 where d is not above 0, NaN included): one instruction,
// where GCC makes a comparison and a mask of `d > zero ? d : zero` (Clang makes the maxps itself). In
// assembly because the AVX2 intrinsics cannot be inlined into this template, which has no target of its
// own; by reference, so no vector crosses a function boundary.
template <int L>
RIVULET_INLINE void clamp_positive(typename VectorLanes<L>::f& d, const typename VectorLanes<L>::f& zero) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    if constexpr (L == 8)
        asm("vmaxps %1, %0, %0" : "+x"(d) : "x"(zero));
    else
        asm("maxps %1, %0" : "+x"(d) : "x"(zero));
#else
    d = d > zero ? d : zero;
#endif
}

// Lane l of v in every lane.
template <class V, int... I>
RIVULET_INLINE void spread_lanes(const V& v, V* out, std::integer_sequence<int, I...>) {
    ((out[I] = v[I] - V{}), ...);
}

// (s[i] - c)^2 / h^2 for i in [0, count), each in every lane of out[i], computed L at a time (s holds
// count rounded up to L).
template <int L>
RIVULET_INLINE void squared_distances(const float* s, float c, float inv_h2, int count,
                                      typename VectorLanes<L>::f* out) {
    using V = typename VectorLanes<L>::f;
    const V cv = c - V{}, inv_h2v = inv_h2 - V{};
    for (int i = 0; i < count; i += L) {
        V d;
        std::memcpy(&d, s + i, sizeof d);
        d -= cv;
        const V d2 = d * d * inv_h2v;
        spread_lanes(d2, out + i, std::make_integer_sequence<int, L>{});
    }
}

// One particle's rows, each as `vectors` (N when N > 0) L-wide vectors from sample ia on (unaligned, so
// a row of n samples costs ceil(n / L) vectors whatever its offset; a lane past the kernel adds q = 0).
// Every row of the square [ja, jb] x [ka, kb] is summed, the corners outside the kernel's circle too
// (they add q = 0): a row costs a few instructions, and trimming each slice to its circle varies the
// rows' count slice by slice, a mispredicted branch per slice that cost more than the rows it saved.
// Every lane does the same IEEE operations in the same order whatever L (max as maxps: 0 where
// qz - dx2 - dy2 is not above 0), so the baseline (L = 4) and AVX2 (L = 8) builds give the same bytes.
template <int L, int N, int R, bool kWeighted>
RIVULET_INLINE void splat_rows(const GroupFrame& g, const Particle& p, int vectors, float* acc) {
    using V = typename VectorLanes<L>::f;
    const V weight = p.weight - V{};
    constexpr int kMaxVectors = N > 0 ? N : int(kLanes) / L;
    const int n = N > 0 ? N : vectors;
    const V zero = V{}, pxv = p.x - V{}, inv_h2v = g.inv_h2 - V{}, one = 1.0f - V{};
    V dx2[kMaxVectors];
    for (int v = 0; v < n; ++v) {
        V sx;
        std::memcpy(&sx, g.sx + p.ia + L * v, sizeof sx);
        const V d = sx - pxv;
        dx2[v] = d * d * inv_h2v;
    }
    // (sy - py)^2 / h^2 of rows [ja, jb] and (sz - pz)^2 / h^2 of slices [ka, kb], each in every lane,
    // once for all of them: a row subtracts its vector from memory.
    const int rows = R > 0 ? R : p.jb - p.ja + 1, slices = p.kb - p.ka + 1;
    V dy2[kGroupEdgeY + L], dz2[kGroupEdgeZ + L];
    squared_distances<L>(g.sy + p.ja, p.y, g.inv_h2, rows, dy2);
    squared_distances<L>(g.sz + p.ka, p.z, g.inv_h2, slices, dz2);
    float* slice = acc + (std::size_t(p.ka) * kGroupEdgeY + std::size_t(p.ja)) * kLanes + p.ia;
    for (int k = 0; k < slices; ++k, slice += kGroupEdgeY * kLanes) {
        const V qz = one - dz2[k];
        V qx[kMaxVectors];
        for (int v = 0; v < n; ++v) qx[v] = qz - dx2[v];
        float* row = slice;
#pragma GCC unroll 16
        for (int r = 0; r < rows; ++r, row += kLanes)
            for (int v = 0; v < n; ++v) {
                V q = qx[v] - dy2[r];
                clamp_positive<L>(q, zero);
                V sum;
                std::memcpy(&sum, row + L * v, sizeof sum);
                if constexpr (kWeighted)
                    sum += q * q * q * weight;
                else
                    sum += q * q * q;
                std::memcpy(row + L * v, &sum, sizeof sum);
            }
    }
}

// A particle whose rows are one vector each, with as many rows per slice as the kernel spans at most
// 2 to 9 voxels (R): the rows' loop unrolled, with no count to test (a loop's test and step were
// a third of a row's instructions).
template <int L, bool kWeighted, int R = 2>
RIVULET_INLINE void splat_rows_of_one(const GroupFrame& g, const Particle& q, float* acc) {
    if constexpr (R > 9)
        splat_rows<L, 1, 0, kWeighted>(g, q, 1, acc);
    else if (q.jb - q.ja + 1 == R)
        splat_rows<L, 1, R, kWeighted>(g, q, 1, acc);
    else
        splat_rows_of_one<L, kWeighted, R + 1>(g, q, acc);
}

// Particles set up a block at a time: their ranges found in lanes, away from the rows' sums.
constexpr std::uint32_t kSetupBlock = 64;

// Sample ranges [first, last] along one axis of the group for n coordinates c: sample_range, then an end
// sample at h or beyond dropped (q <= 0 whatever the other axes: a particle on a sample plane reaches one
// more each side; the margin is far below a sample, so only the end sample can be one). reached[i] &=
// whether any sample is in range. Branch-free over arrays, so the compiler does it in lanes.
RIVULET_INLINE void axis_ranges(const GroupAxis& a, const float* c, std::uint32_t n, float inv_voxel,
                                float h_voxels, float inv_h2, int* first, int* last, int* reached) {
    const float s0 = a.at(0);
    for (std::uint32_t i = 0; i < n; ++i) {
        int f, l;
        const int ok = sample_range((c[i] - s0) * inv_voxel, h_voxels, a.edge, f, l);
        const float df = a.at(f) - c[i], dl = a.at(l) - c[i];
        f += (f < l) & (df * df * inv_h2 >= 1.0f);
        l -= (l > f) & (dl * dl * inv_h2 >= 1.0f);
        first[i] = f, last[i] = l, reached[i] &= ok;
    }
}

// A group's particles summed into `acc`, L samples of a row at a time, each weighted by its volume over
// the grid's where kWeighted.
template <int L, bool kWeighted>
RIVULET_INLINE void splat_particles(const GroupFrame& g, ConstPositions sorted,
                                    const ParticleVolumes& volumes, const std::uint32_t* entries,
                                    std::uint32_t begin, std::uint32_t end, float* acc) {
    float x[kSetupBlock], y[kSetupBlock], z[kSetupBlock], weight[kSetupBlock];
    int ia[kSetupBlock], ib[kSetupBlock], ja[kSetupBlock], jb[kSetupBlock], ka[kSetupBlock], kb[kSetupBlock];
    int reached[kSetupBlock];
    for (std::uint32_t start = begin; start < end; start += kSetupBlock) {
        const std::uint32_t n = std::min(kSetupBlock, end - start);
        for (std::uint32_t i = 0; i < n; ++i) {
            const std::uint32_t e = entries[start + i];
            x[i] = sorted.x[e], y[i] = sorted.y[e], z[i] = sorted.z[e], reached[i] = 1;
            weight[i] = 1.0f;
            if constexpr (kWeighted) {
                const float d = volumes.density[e];
                if (d > 0.0f && d <= std::numeric_limits<float>::max()) weight[i] = g.mass_over_volume / d;
            }
        }
        axis_ranges(g.ax, x, n, g.inv_voxel, g.h_voxels, g.inv_h2, ia, ib, reached);
        axis_ranges(g.ay, y, n, g.inv_voxel, g.h_voxels, g.inv_h2, ja, jb, reached);
        axis_ranges(g.az, z, n, g.inv_voxel, g.h_voxels, g.inv_h2, ka, kb, reached);
        for (std::uint32_t i = 0; i < n; ++i) {
            if (!reached[i]) continue;
            const Particle q{x[i], y[i], z[i], ia[i], ja[i], jb[i], ka[i], kb[i], weight[i]};
            const int vectors = (ib[i] - ia[i]) / L + 1;
            switch (vectors) {
                case 1:
                    splat_rows_of_one<L, kWeighted>(g, q, acc);
                    break;
                case 2:
                    splat_rows<L, 2, 0, kWeighted>(g, q, 2, acc);
                    break;
                case 3:
                    splat_rows<L, 3, 0, kWeighted>(g, q, 3, acc);
                    break;
                default:
                    splat_rows<L, 0, 0, kWeighted>(g, q, vectors, acc);
                    break;
            }
        }
    }
}

// Where a group's sums go: its stored bricks' atlas slots, scaled, with each brick's least and greatest.
struct GroupOut {
    const DensityGrid& grid;
    std::uint32_t a0, b0, c0, na, nb, nc;  // the group's first brick and its bricks inside the grid
    std::span<const std::int32_t> brick_slot;
    std::span<float> atlas, slot_min, slot_max;
    float scale;
};

// One stored brick's samples out of `base` (its first sample in the group's sums), L at a time. Min and
// max are exact, so the order they are taken in changes nothing.
template <int L>
RIVULET_INLINE void copy_out_brick(const GroupOut& o, const float* base, std::uint32_t slot) {
    using V = typename VectorLanes<L>::f;
    constexpr std::uint32_t kVectorSamples = kBrickEdge / L * L;
    const V scale = V{} + o.scale;
    V lo = V{} + base[0] * o.scale, hi = lo;
    float slo = lo[0], shi = lo[0];
    for (std::uint32_t k = 0; k < kBrickEdge; ++k)
        for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
            float* out = o.atlas.data() + atlas_offset(slot, 0, j, k);
            const float* row = base + (std::size_t(k) * kGroupEdgeY + j) * kLanes;
            for (std::uint32_t i = 0; i < kVectorSamples; i += L) {
                V f;
                std::memcpy(&f, row + i, sizeof f);
                f *= scale;
                std::memcpy(out + i, &f, sizeof f);
                lo = f < lo ? f : lo;
                hi = f > hi ? f : hi;
            }
            for (std::uint32_t i = kVectorSamples; i < kBrickEdge; ++i) {
                const float f = row[i] * o.scale;
                out[i] = f;
                slo = std::min(slo, f), shi = std::max(shi, f);
            }
        }
    for (int l = 0; l < L; ++l) slo = std::min(slo, lo[l]), shi = std::max(shi, hi[l]);
    o.slot_min[slot] = slo, o.slot_max[slot] = shi;
}

// A group's particles summed into `acc`, then copied out to its stored bricks.
template <int L>
RIVULET_INLINE void splat_group(const GroupFrame& g, ConstPositions sorted, const ParticleVolumes& volumes,
                                const std::uint32_t* entries, std::uint32_t begin, std::uint32_t end,
                                const GroupOut& o, float* acc) {
    if (volumes.given())
        splat_particles<L, true>(g, sorted, volumes, entries, begin, end, acc);
    else
        splat_particles<L, false>(g, sorted, volumes, entries, begin, end, acc);
    for (std::uint32_t lc = 0; lc < o.nc; ++lc)
        for (std::uint32_t lb = 0; lb < o.nb; ++lb)
            for (std::uint32_t la = 0; la < o.na; ++la) {
                const std::int32_t s = o.brick_slot[o.grid.brick_index(o.a0 + la, o.b0 + lb, o.c0 + lc)];
                if (s < 0) continue;
                const float* base =
                    acc + (std::size_t(lc * kBrickCells) * kGroupEdgeY + lb * kBrickCells) * kLanes +
                    la * kBrickCells;
                copy_out_brick<L>(o, base, static_cast<std::uint32_t>(s));
            }
}

RIVULET_AVX2 void splat_group_avx2(const GroupFrame& g, ConstPositions sorted, const ParticleVolumes& volumes,
                                   const std::uint32_t* entries, std::uint32_t begin, std::uint32_t end,
                                   const GroupOut& o, float* acc) {
    splat_group<8>(g, sorted, volumes, entries, begin, end, o, acc);
}

// Lanes [first, last) of the group's rows that its stored bricks' samples and the vectors of the rows
// reaching them cover (a particle's rows lie in the bricks it reaches, all stored).
void stored_lanes(const DensityGrid& grid, std::uint32_t a0, std::uint32_t b0, std::uint32_t c0,
                  std::uint32_t na, std::uint32_t nb, std::uint32_t nc,
                  std::span<const std::int32_t> brick_slot, std::uint32_t& first, std::uint32_t& last) {
    std::uint32_t lo = na, hi = 0;
    for (std::uint32_t lc = 0; lc < nc; ++lc)
        for (std::uint32_t lb = 0; lb < nb; ++lb)
            for (std::uint32_t la = 0; la < na; ++la)
                if (brick_slot[grid.brick_index(a0 + la, b0 + lb, c0 + lc)] >= 0)
                    lo = std::min(lo, la), hi = std::max(hi, la);
    first = lo < na ? lo * kBrickCells : 0;
    last = lo < na ? std::min<std::uint32_t>((hi + 2) * kBrickCells, kLanes) : 0;
}

}  // namespace

void density_splat_group(const DensityGrid& grid, std::uint32_t group, ConstPositions sorted,
                         const ParticleVolumes& volumes, std::span<const std::uint32_t> entries,
                         std::span<const std::uint32_t> bin_start, std::span<const std::int32_t> brick_slot,
                         std::span<float> atlas, std::span<float> slot_min, std::span<float> slot_max) {
    const DensityGroups gs = density_groups(grid);
    const std::uint32_t ga = group % gs.gx, gb = (group / gs.gx) % gs.gy, gc = group / (gs.gx * gs.gy);
    const std::uint32_t a0 = ga * kGroupBricksX, b0 = gb * kGroupBricksY, c0 = gc * kGroupBricksZ;
    // Bricks of the group inside the grid, per axis, and the last sample index they hold.
    const std::uint32_t na = std::min(kGroupBricksX, grid.bx - a0),
                        nb = std::min(kGroupBricksY, grid.by - b0),
                        nc = std::min(kGroupBricksZ, grid.bz - c0);
    const int ez = int(nc * kBrickCells);
    const std::uint32_t i0 = a0 * kBrickCells, j0 = b0 * kBrickCells, k0 = c0 * kBrickCells;
    // Sample positions exactly as DensityGrid computes them, and every distance from them, so a sample on
    // a face two groups share gets the same bits in both whatever range each visits. Lanes past the group
    // are summed but never read out.
    // y and z run 8 past the group's edge: a particle's rows and slices are read 8 at a time.
    alignas(32) float sx[kLanes];
    float sy[kGroupEdgeY + 8], sz[kGroupEdgeZ + 8];
    for (std::uint32_t i = 0; i < kLanes; ++i) sx[i] = grid.x(i0 + i);
    for (std::uint32_t i = 0; i < kGroupEdgeY + 8; ++i) sy[i] = grid.y(j0 + i);
    for (std::uint32_t i = 0; i < kGroupEdgeZ + 8; ++i) sz[i] = grid.z(k0 + i);
    const float inv_voxel = 1.0f / grid.voxel, h_voxels = grid.h * inv_voxel;
    const float inv_h2 = 1.0f / (grid.h * grid.h);
    // W_poly6 = 315 / (64 pi h^3) q^3 with q = 1 - r^2 / h^2: no h^9 to overflow at small h.
    const double h = grid.h;
    const float scale =
        static_cast<float>(double(grid.volume) * 315.0 / (64.0 * std::numbers::pi * h * h * h));

    // Only the lanes the stored bricks span are cleared (a group is 180 KB of samples).
    alignas(64) float acc[kGroupEdgeZ * kGroupEdgeY * kLanes];
    std::uint32_t first, last;
    stored_lanes(grid, a0, b0, c0, na, nb, nc, brick_slot, first, last);
    for (int k = 0; k <= ez; ++k)
        for (std::uint32_t j = 0; j < kGroupEdgeY; ++j) {
            float* row = acc + (std::size_t(k) * kGroupEdgeY + j) * kLanes;
            std::fill(row + first, row + last, 0.0f);
        }
    const GroupFrame g{sx,
                       sy,
                       sz,
                       inv_voxel,
                       h_voxels,
                       inv_h2,
                       {grid.ox, grid.voxel, i0, int(na * kBrickCells)},
                       {grid.oy, grid.voxel, j0, int(nb * kBrickCells)},
                       {grid.oz, grid.voxel, k0, ez},
                       volumes.mass / grid.volume};
    const GroupOut o{grid, a0, b0, c0, na, nb, nc, brick_slot, atlas, slot_min, slot_max, scale};
    if (cpu_has_avx2())
        splat_group_avx2(g, sorted, volumes, entries.data(), bin_start[group], bin_start[group + 1], o, acc);
    else
        splat_group<4>(g, sorted, volumes, entries.data(), bin_start[group], bin_start[group + 1], o, acc);
}

}  // namespace rivulet
