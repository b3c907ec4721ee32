#include "jobs/density_splat.h"

#include "jobs/cpu_dispatch.h"
#include "jobs/simd4.h"
#include "jobs/vector_lanes.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>

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

// Bricks [first, last] along one axis whose samples lie within h_voxels of coordinate p, conservatively
// (a sample of margin each side). Brick c holds samples [8c, 8c + 8].
inline void brick_range(float p, float o, float inv_voxel, float h_voxels, std::uint32_t n,
                        std::uint32_t& first, std::uint32_t& last) {
    const float t = (p - o) * inv_voxel;
    const float top = float(n * kBrickCells);
    const float a = std::clamp(t - h_voxels - 1.0f, 0.0f, top),
                b = std::clamp(t + h_voxels + 1.0f, 0.0f, top);
    const auto lo = static_cast<std::uint32_t>(a), hi = static_cast<std::uint32_t>(b);
    first = lo >= kBrickCells ? (lo - kBrickCells + kBrickCells - 1) / kBrickCells : 0;
    last = std::min(hi / kBrickCells, n - 1);
}

// Calls f(group, mask) for every group with a brick whose samples lie within h of (x, y, z)
// (conservatively), with the bricks of that group it reaches (density_bin_count_chunk's bit order).
template <bool kMask, class F>
void for_each_reached_group(const DensityGrid& g, float x, float y, float z, F&& f) {
    const float inv_voxel = 1.0f / g.voxel, hv = g.h * inv_voxel;
    std::uint32_t a0, a1, b0, b1, c0, c1;
    brick_range(x, g.ox, inv_voxel, hv, g.bx, a0, a1);
    brick_range(y, g.oy, inv_voxel, hv, g.by, b0, b1);
    brick_range(z, g.oz, inv_voxel, hv, g.bz, c0, c1);
    const std::uint32_t gx = (g.bx + kGroupBricks - 1) / kGroupBricks,
                        gy = (g.by + kGroupBricks - 1) / kGroupBricks;
    // Local bricks of group G along one axis that [lo, hi] covers, as bits.
    const auto bits = [](std::uint32_t G, std::uint32_t lo, std::uint32_t hi) {
        const std::uint32_t first = G * kGroupBricks;
        std::uint32_t m = (1u << kGroupBricks) - 1;
        if (lo > first) m &= ~0u << (lo - first);
        if (hi < first + kGroupBricks - 1) m &= (2u << (hi - first)) - 1;
        return m;
    };
    // The 3D mask as bit tricks on 2 x 2 x 2 bricks: the x bits repeated in each of the four (y, z)
    // slots, kept where the slot's y and z bricks are both reached.
    static_assert(kGroupBricks == 2, "the brick mask below assumes 2 x 2 x 2 bricks per group");
    constexpr std::uint8_t kSpread[16] = {0x00, 0x03, 0x0c, 0x0f, 0x30, 0x33, 0x3c, 0x3f,
                                          0xc0, 0xc3, 0xcc, 0xcf, 0xf0, 0xf3, 0xfc, 0xff};
    for (std::uint32_t C = c0 / kGroupBricks; C <= c1 / kGroupBricks; ++C) {
        const std::uint32_t mc = kMask ? bits(C, c0, c1) : 0;
        for (std::uint32_t B = b0 / kGroupBricks; B <= b1 / kGroupBricks; ++B) {
            std::uint32_t yz = 0;
            if constexpr (kMask) {
                const std::uint32_t mb = bits(B, b0, b1);
                yz = kSpread[((mc & 1u) ? mb : 0u) | ((mc & 2u) ? mb << 2 : 0u)];
            }
            for (std::uint32_t A = a0 / kGroupBricks; A <= a1 / kGroupBricks; ++A)
                f((C * gy + B) * gx + A, kMask ? (bits(A, a0, a1) * 0x55u) & yz : 0u);
        }
    }
}

}  // namespace

DensityGroups density_groups(const DensityGrid& grid) {
    return {(grid.bx + kGroupBricks - 1) / kGroupBricks, (grid.by + kGroupBricks - 1) / kGroupBricks,
            (grid.bz + kGroupBricks - 1) / kGroupBricks};
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
                             std::span<std::uint8_t> masks) {
    for (std::size_t i = 0; i < p.size(); ++i)
        for_each_reached_group<true>(grid, p.x[i], p.y[i], p.z[i], [&](std::uint32_t g, std::uint32_t m) {
            ++counts[g];
            masks[g] = static_cast<std::uint8_t>(masks[g] | m);
        });
}

void density_bin_scatter_chunk(const DensityGrid& grid, ConstPositions p, std::span<std::uint32_t> cursors,
                               const SortedPositionsOut& sorted) {
    for (std::size_t i = 0; i < p.size(); ++i) {
        const float x = p.x[i], y = p.y[i], z = p.z[i];
        for_each_reached_group<false>(grid, x, y, z, [&](std::uint32_t g, std::uint32_t) {
            const std::uint32_t at = cursors[g]++;
            sorted.x[at] = x, sorted.y[at] = y, sorted.z[at] = z;
        });
    }
}

std::uint32_t density_allocate_bricks(const DensityGrid& grid, std::span<const std::uint8_t> masks,
                                      std::span<std::int32_t> brick_slot, std::span<std::uint32_t> slot_brick,
                                      std::span<std::uint32_t> groups_out, std::uint32_t& group_count) {
    const DensityGroups gs = density_groups(grid);
    std::uint32_t slots = 0;
    for (std::uint32_t c = 0; c < grid.bz; ++c)
        for (std::uint32_t b = 0; b < grid.by; ++b) {
            const std::uint32_t row = ((c / kGroupBricks) * gs.gy + b / kGroupBricks) * gs.gx;
            const std::uint32_t shift = ((c % kGroupBricks) * kGroupBricks + b % kGroupBricks) * kGroupBricks;
            for (std::uint32_t a = 0; a < grid.bx; ++a) {
                const std::uint32_t brick = grid.brick_index(a, b, c);
                if (!(masks[row + a / kGroupBricks] >> (shift + a % kGroupBricks) & 1u)) {
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

// A group row's samples in whole 8-wide vectors: a row read from any sample of the group in 4- or 8-wide
// vectors stays inside it (the lanes past the group are summed but never read out).
constexpr std::uint32_t kLanes = (kGroupEdge + 7) / 8 * 8;
constexpr std::uint32_t kVectors = (kGroupEdge + 3) / 4;
constexpr std::uint32_t kWideVectors = (kGroupEdge + 7) / 8;

// A range test's margin, in samples: far above the rounding of the distances (about 1e-4 samples at
// --max-dim 4096), so every sample whose computed q is positive is visited in every group that holds it
// and the faces groups share get the same sums; far below a sample, so it rarely visits one more.
constexpr float kMargin = 0.05f;

// Sample indices [first, last] within [0, edge] of a group row at most r samples from t (t the
// coordinate in samples from the group's first): floor(t - r) + 1 to floor(t + r), widened by kMargin.
// Truncation instead of floor, which is a library call on the x86-64 baseline, where the value is
// known to be non-negative. False when none.
bool sample_range(float t, float r, int edge, int& first, int& last) {
    const float a = t - r - kMargin, b = t + r + kMargin;
    if (!(b >= 0.0f) || !(a <= float(edge))) return false;
    first = a >= 0.0f ? static_cast<int>(a) + 1 : 0;
    last = b < float(edge) ? static_cast<int>(b) : edge;
    return first <= last;
}

struct GroupFrame {
    const float* sx;  // kLanes sample x coordinates
    const float* sy;  // kLanes sample y coordinates
    const float* sz;  // kGroupEdge
    float inv_voxel, h_voxels, inv_h2;
};
struct Particle {
    float x, y, z;
    float ty;                // y in samples from the group's first
    int ia, ja, jb, ka, kb;  // sample ranges it can reach; x: [ia, ia + 4 N)
};

// One particle's rows: N vectors from sample ia on in each (unaligned, so a row of n samples costs
// ceil(n / 4) vectors whatever its offset; a lane past the kernel adds q = 0).
template <int N>
void splat_rows(const GroupFrame& g, const Particle& p, float* acc) {
    using simd::F4;
    const F4 zero = simd::splat(0.0f), pxv = simd::splat(p.x), inv_h2v = simd::splat(g.inv_h2);
    F4 dx2[N];
    for (int v = 0; v < N; ++v) {
        const F4 d = simd::load(g.sx + p.ia + 4 * v) - pxv;
        dx2[v] = d * d * inv_h2v;
    }
    // (sy - py)^2 / h^2 of the vectors holding rows [ja, jb], once for all its slices.
    alignas(16) float dy2[kLanes];
    const F4 pyv = simd::splat(p.y);
    for (int v = p.ja >> 2; v <= p.jb >> 2; ++v) {
        const F4 d = simd::load(g.sy + 4 * v) - pyv;
        simd::store(dy2 + 4 * v, d * d * inv_h2v);
    }
    for (int k = p.ka; k <= p.kb; ++k) {
        const float qz = 1.0f - (g.sz[k] - p.z) * (g.sz[k] - p.z) * g.inv_h2;
        if (!(qz > 0)) continue;
        // The slice's circle of rows. A row it misses by rounding has q <= 0 on every lane, and adds 0.
        int jlo, jhi;
        if (!sample_range(p.ty, std::sqrt(qz) * g.h_voxels, kGroupEdge - 1, jlo, jhi)) continue;
        jlo = std::max(jlo, p.ja), jhi = std::min(jhi, p.jb);
        float* slice = acc + std::size_t(k) * kGroupEdge * kLanes + p.ia;
        for (int j = jlo; j <= jhi; ++j) {
            const float qzy = qz - dy2[j];
            float* row = slice + std::size_t(j) * kLanes;
            const F4 t = simd::splat(qzy);
            for (int v = 0; v < N; ++v) {
                const F4 q = simd::max(t - dx2[v], zero);
                simd::store(row + 4 * v, simd::load(row + 4 * v) + q * q * q);
            }
        }
    }
}

// The same rows eight lanes at a time (built for AVX2 inside splat_particles_avx2): the same operations
// per sample in the same order (max as maxps: 0 where t - dx2 is not above 0), so the same bytes; a row of
// up to eight samples is one vector instead of two.
template <int N>
RIVULET_INLINE void splat_rows_wide(const GroupFrame& g, const Particle& p, float* acc) {
    using F8 = VectorLanes<8>::f;
    const F8 zero = F8{} + 0.0f, pxv = F8{} + p.x, inv_h2v = F8{} + g.inv_h2;
    F8 dx2[N];
    for (int v = 0; v < N; ++v) {
        F8 sx;
        std::memcpy(&sx, g.sx + p.ia + 8 * v, sizeof sx);
        const F8 d = sx - pxv;
        dx2[v] = d * d * inv_h2v;
    }
    alignas(16) float dy2[kLanes];
    for (int j = p.ja; j <= p.jb; ++j) dy2[j] = (g.sy[j] - p.y) * (g.sy[j] - p.y) * g.inv_h2;
    for (int k = p.ka; k <= p.kb; ++k) {
        const float qz = 1.0f - (g.sz[k] - p.z) * (g.sz[k] - p.z) * g.inv_h2;
        if (!(qz > 0)) continue;
        int jlo, jhi;
        if (!sample_range(p.ty, std::sqrt(qz) * g.h_voxels, kGroupEdge - 1, jlo, jhi)) continue;
        jlo = std::max(jlo, p.ja), jhi = std::min(jhi, p.jb);
        float* slice = acc + std::size_t(k) * kGroupEdge * kLanes + p.ia;
        for (int j = jlo; j <= jhi; ++j) {
            const F8 t = F8{} + (qz - dy2[j]);
            float* row = slice + std::size_t(j) * kLanes;
            for (int v = 0; v < N; ++v) {
                const F8 d = t - dx2[v];
                const F8 q = d > zero ? d : zero;
                F8 sum;
                std::memcpy(&sum, row + 8 * v, sizeof sum);
                sum += q * q * q;
                std::memcpy(row + 8 * v, &sum, sizeof sum);
            }
        }
    }
}

// A group's particles summed into `acc`, four or (kWide) eight samples of a row at a time.
template <bool kWide>
RIVULET_INLINE void splat_particles(const GroupFrame& g, ConstPositions sorted, std::uint32_t begin,
                                    std::uint32_t end, int ex, int ey, int ez, float* acc) {
    for (std::uint32_t p = begin; p < end; ++p) {
        const float px = sorted.x[p], py = sorted.y[p], pz = sorted.z[p];
        const float ty = (py - g.sy[0]) * g.inv_voxel;
        int ia, ib, ja, jb, ka, kb;
        if (!sample_range((px - g.sx[0]) * g.inv_voxel, g.h_voxels, ex, ia, ib) ||
            !sample_range(ty, g.h_voxels, ey, ja, jb) ||
            !sample_range((pz - g.sz[0]) * g.inv_voxel, g.h_voxels, ez, ka, kb))
            continue;
        const Particle q{px, py, pz, ty, ia, ja, jb, ka, kb};
        if constexpr (kWide) {
            switch ((ib - ia) >> 3) {
                case 0:
                    splat_rows_wide<1>(g, q, acc);
                    break;
                case 1:
                    splat_rows_wide<2>(g, q, acc);
                    break;
                default:
                    splat_rows_wide<kWideVectors>(g, q, acc);
                    break;
            }
            continue;
        }
        switch ((ib - ia) >> 2) {
            case 0:
                splat_rows<1>(g, q, acc);
                break;
            case 1:
                splat_rows<2>(g, q, acc);
                break;
            case 2:
                splat_rows<3>(g, q, acc);
                break;
            case 3:
                splat_rows<4>(g, q, acc);
                break;
            default:
                splat_rows<kVectors>(g, q, acc);
                break;
        }
    }
}

RIVULET_AVX2 void splat_particles_avx2(const GroupFrame& g, ConstPositions sorted, std::uint32_t begin,
                                       std::uint32_t end, int ex, int ey, int ez, float* acc) {
    splat_particles<true>(g, sorted, begin, end, ex, ey, ez, acc);
}

}  // namespace

void density_splat_group(const DensityGrid& grid, std::uint32_t group, ConstPositions sorted,
                         std::span<const std::uint32_t> bin_start, std::span<const std::int32_t> brick_slot,
                         std::span<float> atlas, std::span<float> slot_min, std::span<float> slot_max) {
    const DensityGroups gs = density_groups(grid);
    const std::uint32_t ga = group % gs.gx, gb = (group / gs.gx) % gs.gy, gc = group / (gs.gx * gs.gy);
    const std::uint32_t a0 = ga * kGroupBricks, b0 = gb * kGroupBricks, c0 = gc * kGroupBricks;
    // Bricks of the group inside the grid, per axis, and the last sample index they hold.
    const std::uint32_t na = std::min(kGroupBricks, grid.bx - a0), nb = std::min(kGroupBricks, grid.by - b0),
                        nc = std::min(kGroupBricks, grid.bz - c0);
    const int ex = int(na * kBrickCells), ey = int(nb * kBrickCells), ez = int(nc * kBrickCells);
    const std::uint32_t i0 = a0 * kBrickCells, j0 = b0 * kBrickCells, k0 = c0 * kBrickCells;
    // Sample positions exactly as DensityGrid computes them, and every distance from them, so a sample on
    // a face two groups share gets the same bits in both whatever range each visits. Lanes past the group
    // are summed but never read out.
    alignas(16) float sx[kLanes];
    alignas(16) float sy[kLanes];
    float sz[kGroupEdge];
    for (std::uint32_t i = 0; i < kLanes; ++i) sx[i] = grid.x(i0 + i), sy[i] = grid.y(j0 + i);
    for (std::uint32_t i = 0; i < kGroupEdge; ++i) sz[i] = grid.z(k0 + i);
    const float inv_voxel = 1.0f / grid.voxel, h_voxels = grid.h * inv_voxel;
    const float inv_h2 = 1.0f / (grid.h * grid.h);
    // W_poly6 = 315 / (64 pi h^3) q^3 with q = 1 - r^2 / h^2: no h^9 to overflow at small h.
    const double h = grid.h;
    const float scale =
        static_cast<float>(double(grid.volume) * 315.0 / (64.0 * std::numbers::pi * h * h * h));

    alignas(64) float acc[kGroupEdge * kGroupEdge * kLanes];
    std::fill(acc, acc + std::size_t(ez + 1) * kGroupEdge * kLanes, 0.0f);
    const GroupFrame g{sx, sy, sz, inv_voxel, h_voxels, inv_h2};
    if (cpu_has_avx2())
        splat_particles_avx2(g, sorted, bin_start[group], bin_start[group + 1], ex, ey, ez, acc);
    else
        splat_particles<false>(g, sorted, bin_start[group], bin_start[group + 1], ex, ey, ez, acc);
    for (std::uint32_t lc = 0; lc < nc; ++lc)
        for (std::uint32_t lb = 0; lb < nb; ++lb)
            for (std::uint32_t la = 0; la < na; ++la) {
                const std::int32_t s = brick_slot[grid.brick_index(a0 + la, b0 + lb, c0 + lc)];
                if (s < 0) continue;
                const auto slot = static_cast<std::uint32_t>(s);
                const float* base = acc +
                                    (std::size_t(lc * kBrickCells) * kGroupEdge + lb * kBrickCells) * kLanes +
                                    la * kBrickCells;
                float lo = base[0] * scale, hi = lo;
                for (std::uint32_t k = 0; k < kBrickEdge; ++k)
                    for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
                        float* out = atlas.data() + atlas_offset(slot, 0, j, k);
                        const float* row = base + (std::size_t(k) * kGroupEdge + j) * kLanes;
                        for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                            const float f = row[i] * scale;
                            out[i] = f;
                            lo = std::min(lo, f), hi = std::max(hi, f);
                        }
                    }
                slot_min[slot] = lo, slot_max[slot] = hi;
            }
}

}  // namespace rivulet
