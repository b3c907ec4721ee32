// Marching slices (Janisz §3.2) against a brute-force marching-cubes oracle over the full grid: same
// triangles; closed surfaces watertight across block borders; right geometry; same bytes at any thread
// count; bad settings and inputs rejected.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <utility>
#include <vector>

#include "jobs/bin_sort.h"
#include "jobs/block_bins.h"
#include "jobs/cpu_dispatch.h"
#include "jobs/lookup_cache.h"
#include "jobs/marching_tables.h"
#include "jobs/mesh_hash.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/slices_jobs.h"
#include "runtime/lib/thread_control.h"
#include "support/reference_marching_cubes.h"
#include "support/test_support.h"
#include "systems/slices/slices_extractor.h"

using namespace rivulet;

namespace {

using Cloud = test::PointCloud;

// The classic field by default: these tests pin the extractor's mechanics to its fixed R_c = 2 radii;
// the spacing field's rule is tested in test_slices_field.cpp, its mechanics here where named.
SlicesSettings settings_for(float radius, std::uint32_t block, float voxel = 0,
                            SliceField field = SliceField::kClassic) {
    SlicesSettings s;
    s.field = field;
    s.radius = radius;
    s.block_cubes = block;
    s.voxel = voxel;
    return s;
}

std::vector<float> positions_of(const SurfaceMesh& m) {
    return test::strided_positions({m.vertices6.data(), 6 * m.vertex_count}, 6);
}
std::vector<std::uint32_t> indices_of(const SurfaceMesh& m) {
    return {m.indices.data(), m.indices.data() + m.index_count};
}

std::uint64_t hash_of(const SurfaceMesh& m) {
    Hasher h;
    h.add(m.view().vertices);
    h.add(m.view().indices);
    return h.digest();
}

// Clusters of particles (Gaussian offsets) far enough apart to stay separate, and a few loners.
Cloud blobs(unsigned seed, int clusters, int per_cluster, float radius) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> where(0.0f, 1.0f);
    std::normal_distribution<float> around(0.0f, 1.6f * radius);
    Cloud c;
    for (int k = 0; k < clusters; ++k) {
        const float cx = 14 * radius * float(k % 3), cy = 14 * radius * float(k / 3),
                    cz = 6 * radius * where(rng);
        for (int i = 0; i < per_cluster; ++i) c.add(cx + around(rng), cy + around(rng), cz + around(rng));
    }
    for (int i = 0; i < 3; ++i)
        c.add(-10 * radius - 6 * radius * float(i), 30 * radius * where(rng), 20 * radius * where(rng));
    return c;
}

struct Extracted {
    SurfaceMesh mesh;
    SliceGrid grid;
    float iso = 0;
    SlicesStats stats;
};

Extracted extract(const Cloud& c, const SlicesSettings& s) {
    SlicesExtractor ex(s, c.size());
    Extracted e;
    ex.extract_serial(c.pos(), e.mesh);
    e.grid = ex.grid();
    e.iso = ex.iso();
    e.stats = ex.stats();
    return e;
}

void expect_matches_reference(const Cloud& c, const SlicesSettings& s) {
    const Extracted e = extract(c, s);
    const test::ReferenceMesh ref = test::reference_marching_cubes(e.grid, e.iso, c.pos());
    ASSERT_GT(ref.indices.size(), 0u);
    ASSERT_EQ(e.mesh.index_count, ref.indices.size()) << "block " << s.block_cubes;
    EXPECT_EQ(e.mesh.vertex_count, ref.positions.size() / 3) << "every shared edge is one vertex";
    const auto got = test::canonical_triangles(positions_of(e.mesh), 3, indices_of(e.mesh));
    const auto want = test::canonical_triangles(ref.positions, 3, ref.indices);
    std::size_t bad = 0;
    for (std::size_t t = 0; t < got.size(); ++t)
        for (int a = 0; a < 9; ++a)
            if (std::abs(got[t][a] - want[t][a]) > 1e-6f) ++bad;
    EXPECT_EQ(bad, 0u) << "block " << s.block_cubes;
    EXPECT_EQ(test::count_open_edges(positions_of(e.mesh), indices_of(e.mesh)), 0u)
        << "watertight, block " << s.block_cubes;
}

double signed_volume(const SurfaceMesh& m) {
    double v = 0;
    const float* p = m.vertices6.data();
    for (std::size_t t = 0; t < m.index_count; t += 3) {
        const float* a = p + 6 * m.indices[t];
        const float* b = p + 6 * m.indices[t + 1];
        const float* c = p + 6 * m.indices[t + 2];
        v += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
              double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
              double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
             6.0;
    }
    return v;
}

}  // namespace

TEST(MarchingTables, EveryCaseIsAClosedConsistentPatch) {
    const MarchingTables& t = marching_tables();
    EXPECT_EQ(t.triangle_count[0], 0);
    EXPECT_EQ(t.triangle_count[255], 0);
    for (int m = 1; m < 255; ++m) {
        ASSERT_GT(t.triangle_count[m], 0) << m;
        // The triangles use exactly the crossed edges.
        int used = 0;
        for (int i = 0; i < t.triangle_count[m] * 3; ++i) used |= 1 << t.triangles[m][i];
        EXPECT_EQ(used, t.edge_mask[m]) << m;
        // Within the cube the patch is oriented and manifold: no directed edge twice.
        std::vector<std::pair<int, int>> directed;
        for (int i = 0; i < t.triangle_count[m]; ++i)
            for (int k = 0; k < 3; ++k)
                directed.emplace_back(t.triangles[m][i * 3 + k], t.triangles[m][i * 3 + (k + 1) % 3]);
        std::sort(directed.begin(), directed.end());
        EXPECT_EQ(std::adjacent_find(directed.begin(), directed.end()), directed.end()) << m;
        // A crossed cube edge joins an inside and an outside corner.
        for (int e = 0; e < 12; ++e) {
            const bool a = (m >> t.edge_corner[e][0]) & 1, b = (m >> t.edge_corner[e][1]) & 1;
            EXPECT_EQ(a != b, ((t.edge_mask[m] >> e) & 1) != 0) << m << " edge " << e;
        }
    }
}

// SliceGrid::block_of divides corner indices by the block edge with a multiply: exact for every block
// edge the settings allow and every corner index a grid can have (below 2^21).
TEST(BlockBins, BlockOfIsExactDivision) {
    std::mt19937 rng(11);
    std::uniform_int_distribution<std::uint32_t> corner(0, (1u << 21) - 1);
    for (std::uint32_t n = 2; n <= 128; ++n) {
        SliceGrid g;
        g.set_block_cubes(n);
        for (std::uint32_t c = 0; c < (1u << 14); ++c) ASSERT_EQ(g.block_of(c), c / n) << c << " / " << n;
        for (int t = 0; t < 20000; ++t) {
            const std::uint32_t c = corner(rng);
            ASSERT_EQ(g.block_of(c), c / n) << c << " / " << n;
        }
        ASSERT_EQ(g.block_of((1u << 21) - 1), ((1u << 21) - 1) / n) << n;
    }
}

// SliceGrid::cell multiplies by 1 / voxel, so a coordinate within an ulp of a corner plane may fall in the
// cube on the other side; the reach's corner of margin must still hold every corner the kernel can see
// (float r^2 < R_c^2, here with the x and y terms zero: the widest reach along one axis).
TEST(BlockBins, CellsByAMultiplyStayWithinOneOfFloorAndTheReachHoldsEveryCornerInRc) {
    for (const float voxel : {0.05f, 0.037f, 0.1f / 3.0f, 0.002862f})
        for (const float rc_voxels : {4.0f, 3.3f, 2.0f}) {
            SliceGrid g;
            g.set_voxel(voxel);
            g.rc = rc_voxels * voxel;
            g.reach = static_cast<std::int32_t>(std::ceil(g.rc / voxel));
            g.oz = -1.234f;
            const SliceKernel f = SliceKernel::from_rc(g.rc);
            for (std::int32_t m = 0; m < 400; ++m)
                for (int ulps = -3; ulps <= 3; ++ulps) {
                    float p = g.cz(m);
                    for (int u = 0; u < std::abs(ulps); ++u) p = std::nextafter(p, ulps > 0 ? 1e30f : -1e30f);
                    const std::int32_t c = SliceGrid::cell(p, g.oz, g.inv_voxel);
                    const double exact = std::floor((double(p) - double(g.oz)) / double(voxel));
                    ASSERT_LE(std::abs(double(c) - exact), 1.0) << p;
                    for (std::int32_t q = c - g.reach - 4; q <= c + g.reach + 5; ++q) {
                        const float dz = p - g.cz(q);
                        if (!(dz * dz < f.rc2)) continue;  // the kernel adds +0 there
                        ASSERT_TRUE(q >= c - g.reach && q <= c + g.reach + 1)
                            << "corner " << q << " of a particle in cell " << c << ", voxel " << voxel;
                    }
                }
        }
}

TEST(BlockBins, BlocksOfTwoReachPlusTwoListAParticleInAtMostEightBlocksInIndexOrder) {
    const Cloud c = blobs(4, 6, 200, 0.05f);
    SlicesExtractor ex(settings_for(0.05f, 16), c.size());  // reach 4: 16 >= 2 * 4 + 2
    ex.begin_frame(c.pos());
    EXPECT_LE(max_blocks_per_particle(ex.grid()), 8u);
    std::vector<std::uint32_t> per_particle(c.size());
    for (std::size_t i = 0; i < c.size(); ++i) {
        const ParticleReach r = particle_reach(ex.grid(), c.x[i], c.y[i], c.z[i]);
        std::uint32_t blocks = 1;
        for (int a = 0; a < 3; ++a) blocks *= std::uint32_t(r.bhi[a] - r.blo[a] + 1);
        EXPECT_GE(blocks, 1u);
        EXPECT_LE(blocks, 8u);
    }
    // Counted per chunk, prefixed, scattered: ascending particle index within each block.
    std::vector<std::uint32_t> counts(ex.grid().blocks()), cursors(ex.grid().blocks()),
        offsets(ex.grid().blocks() + 1);
    block_count_chunk(ex.grid(), c.pos(), counts);
    const std::uint32_t total = bin_prefix(ex.grid().blocks(), 1, counts, cursors, offsets);
    std::vector<std::uint32_t> entries(total);
    std::vector<float> ex_(total), ey(total), ez(total);
    block_scatter_chunk(ex.grid(), c.pos(), 0, cursors, {entries, ex_, ey, ez});
    for (std::uint32_t b = 0; b < ex.grid().blocks(); ++b)
        for (std::uint32_t e = offsets[b] + 1; e < offsets[b + 1]; ++e) EXPECT_LT(entries[e - 1], entries[e]);
    EXPECT_GE(total, c.size());
}

TEST(BlockBins, MaxBlocksPerParticleBoundsEveryParticleAndIsReachedBySmallBlocks) {
    const Cloud c = blobs(7, 8, 300, 0.05f);
    for (const std::uint32_t n : {5u, 9u, 10u, 16u, 40u}) {
        SlicesExtractor ex(settings_for(0.05f, n), c.size());
        ex.begin_frame(c.pos());
        std::uint32_t most = 0;
        for (std::size_t i = 0; i < c.size(); ++i) {
            const ParticleReach r = particle_reach(ex.grid(), c.x[i], c.y[i], c.z[i]);
            std::uint32_t blocks = 1;
            for (int a = 0; a < 3; ++a) blocks *= std::uint32_t(r.bhi[a] - r.blo[a] + 1);
            most = std::max(most, blocks);
        }
        EXPECT_LE(most, max_blocks_per_particle(ex.grid())) << n;
        if (n == 9) {
            EXPECT_EQ(max_blocks_per_particle(ex.grid()), 27u);  // 2 reach + 1 = 9 corners apart
        }
    }
}

TEST(MarchingSlices, MatchesBruteForceOnRandomBlobs) {
    for (unsigned seed : {1u, 2u}) {
        const Cloud c = blobs(seed, 5, 40, 0.1f);
        for (std::uint32_t block : {8u, 16u}) {
            expect_matches_reference(c, settings_for(0.1f, block));
            // R_c and the reach set at the first frame from the measured spacing.
            expect_matches_reference(c, settings_for(0.1f, block, 0, SliceField::kSpacing));
        }
    }
}

// The field's reach bounds (which blocks list a particle, which slices its column entries serve) hold
// for voxels that do not divide R_c, and for particles lying exactly on corner planes (cell borders).
TEST(MarchingSlices, MatchesBruteForceWhenVoxelsDoNotDivideRcAndOnCellBorders) {
    const Cloud c = blobs(7, 4, 40, 0.1f);
    for (float voxel : {0.037f, 0.061f}) expect_matches_reference(c, settings_for(0.1f, 8, voxel));
    Cloud lattice;  // spacing 4 voxels of 0.05: every particle on a corner of the grid
    for (int i = 0; i < 6; ++i)
        for (int j = 0; j < 5; ++j)
            for (int k = 0; k < 4; ++k) lattice.add(0.2f * float(i), 0.2f * float(j), 0.2f * float(k));
    for (std::uint32_t block : {8u, 12u}) expect_matches_reference(lattice, settings_for(0.1f, block, 0.05f));
}

namespace {

// The blob cloud of the per-block tests, extracted once (for its grid), and the lookup cache of any of
// its blocks, built as the extractor builds it.
struct BlockCaches {
    Cloud c = blobs(3, 5, 40, 0.1f);
    SliceGrid g;
    std::vector<std::uint32_t> order, counts, offsets;
    std::vector<std::int32_t> mids;
    std::vector<std::uint16_t> rows;
    std::vector<ColumnEntry> entries;
    float iso = 0;

    BlockCaches() {
        SlicesExtractor ex(settings_for(0.1f, 8), c.size());
        SurfaceMesh m;
        ex.extract_serial(c.pos(), m);
        g = ex.grid();
        iso = ex.iso();
        order.resize(c.size()), mids.resize(c.size()), counts.resize(lookup_sort_slots(g));
        offsets.resize(lookup_offset_slots(g)), rows.resize(c.size() * lookup_row_slots(g));
    }
    LookupCacheView build(std::uint32_t bi, std::uint32_t bj, std::uint32_t bk) {
        const LookupScratch ls{order, mids, counts, rows};
        entries.resize(build_lookup_cache(g, bi, bj, bk, c.pos(), ls, offsets, {}));
        build_lookup_cache(g, bi, bj, bk, c.pos(), ls, offsets, entries);
        return {offsets, entries, g.reach, lookup_groups(g), (g.n + 1) * (g.n + 1)};
    }
};

}  // namespace

TEST(MarchingSlices, ColumnAndSignEvaluationsMatchCornerEvaluation) {
    BlockCaches caches;
    const SliceGrid& g = caches.g;
    const SliceKernel f = SliceKernel::from_rc(g.rc);
    const std::uint32_t n = g.n;
    // cache_column reads pz and writes out in whole fours/eights
    std::vector<float> pz(n + 8), column(n + 8), column8(n + 8);
    std::size_t nonzero = 0;
    for (std::uint32_t b = 0; b < g.blocks(); ++b) {
        const std::uint32_t bi = b % g.bx, bj = (b / g.bx) % g.by, bk = b / (g.bx * g.by);
        const LookupCacheView view = caches.build(bi, bj, bk);
        const std::int32_t k0 = std::int32_t(bk * n);
        for (std::uint32_t k = 0; k <= n; ++k) pz[k] = g.cz(k0 + std::int32_t(k));
        for (std::uint32_t j = 0; j <= n; ++j)
            for (std::uint32_t i = 0; i <= n; ++i) {
                cache_column(view, n, i, j, 0, std::int32_t(n), pz.data(), f, column.data());
                // Eight slices a pass (the AVX2 build: walks, face scans, sweep runs): the same bits.
                cache_column<8>(view, n, i, j, 0, std::int32_t(n), pz.data(), f, column8.data());
                ASSERT_EQ(std::memcmp(column.data(), column8.data(), (n + 1) * sizeof(float)), 0) << b;
                for (std::uint32_t k = 0; k <= n; ++k) {
                    const float want = cache_field(view, n, i, j, std::int32_t(k), pz[k], f);
                    ASSERT_EQ(std::memcmp(&want, &column[k], sizeof(float)), 0) << b << " " << i << " " << j;
                    // The sweep's runs: up to four (baseline) or eight (AVX2) slices from any start.
                    float run[4], run_up8[8];
                    const std::uint32_t to = std::min(k + 3, n), to8 = std::min(k + 7, n);
                    cache_column(view, n, i, j, std::int32_t(k), std::int32_t(to), pz.data() + k, f, run);
                    cache_column<8>(view, n, i, j, std::int32_t(k), std::int32_t(to8), pz.data() + k, f,
                                    run_up8);
                    for (std::uint32_t t = k; t <= to; ++t)
                        ASSERT_EQ(std::memcmp(&run[t - k], &column[t], sizeof(float)), 0) << b << " " << t;
                    for (std::uint32_t t = k; t <= to8; ++t)
                        ASSERT_EQ(std::memcmp(&run_up8[t - k], &column[t], sizeof(float)), 0)
                            << b << " " << t;
                    // The walks' runs of eight, downwards from slice k.
                    float run8[8];
                    const std::uint32_t from = k >= 7 ? k - 7 : 0;
                    cache_column<8>(view, n, i, j, std::int32_t(from), std::int32_t(k), pz.data() + from, f,
                                    run8);
                    for (std::uint32_t t = from; t <= k; ++t)
                        ASSERT_EQ(std::memcmp(&run8[t - from], &column[t], sizeof(float)), 0)
                            << b << " " << t;
                    nonzero += want > 0.0f;
                }
            }
    }
    EXPECT_GT(nonzero, 1000u);
}

namespace {

// 7 x 7 x 7 particles `spacing` apart, each moved by up to 0.03 on every axis (fixed seed).
Cloud jittered_lattice(float spacing) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> jitter(-0.03f, 0.03f);
    Cloud c;
    for (int k = 0; k < 7; ++k)
        for (int j = 0; j < 7; ++j)
            for (int i = 0; i < 7; ++i)
                c.add(spacing * float(i) + jitter(rng), spacing * float(j) + jitter(rng),
                      spacing * float(k) + jitter(rng));
    return c;
}

}  // namespace

TEST(MarchingSlices, WatertightAcrossBlockBordersForBlockSizes8To32) {
    // A cube of jittered particles 1.6 radii apart (dense enough to hold no empty cavity, see
    // docs/marching_slices.md): closed, many blocks at n = 8.
    const Cloud c = jittered_lattice(0.16f);
    std::uint64_t first_triangles = 0;
    for (std::uint32_t block : {8u, 16u, 32u}) {
        const Extracted e = extract(c, settings_for(0.1f, block));
        EXPECT_EQ(test::count_open_edges(positions_of(e.mesh), indices_of(e.mesh)), 0u) << block;
        EXPECT_GT(signed_volume(e.mesh), 0.0) << block;
        if (block == 8) {
            EXPECT_GT(e.stats.active_blocks, 8u);
            first_triangles = e.mesh.triangle_count();
        }
        EXPECT_EQ(e.mesh.triangle_count(), first_triangles) << "the mesh does not depend on the block size";
    }
    expect_matches_reference(c, settings_for(0.1f, 8));
}

TEST(MarchingSlices, ExhaustiveSeedsFindEmptyCavitiesToo) {
    // A jittered lattice 2 radii apart holds small bubbles of F < iso that enclose no particle. The
    // default seeds need not find those lying inside one block; exhaustive seeds match the oracle.
    const Cloud c = jittered_lattice(0.2f);
    SlicesSettings s = settings_for(0.1f, 16);
    const Extracted fast = extract(c, s);
    s.exhaustive_seeds = true;
    expect_matches_reference(c, s);
    const Extracted full = extract(c, s);
    EXPECT_LT(fast.mesh.triangle_count(), full.mesh.triangle_count()) << "this cloud has cavities";
    EXPECT_EQ(test::count_open_edges(positions_of(fast.mesh), indices_of(fast.mesh)), 0u);
}

TEST(MarchingSlices, FindsSurfaceTheWalkCannotReach) {
    // One block (n = 64): no face seeds, so the walk must carry everything. A dome of particles (a
    // hemispherical shell, open at the bottom): walks from the top hit the inner ceiling, a local maximum;
    // the sweep has to follow the surface down to the rim, below every slab it started in.
    Cloud dome;
    for (int a = 0; a < 24; ++a)
        for (int b = 0; b <= 6; ++b) {
            const float th = 6.2831853f * float(a) / 24.0f, ph = 1.5707963f * float(b) / 6.0f;
            dome.add(0.8f * std::cos(th) * std::cos(ph), 0.8f * std::sin(th) * std::cos(ph),
                     0.8f * std::sin(ph));
        }
    dome.add(0, 0, 0.8f);
    expect_matches_reference(dome, settings_for(0.1f, 64));
    // Many blocks: the upper blocks hold only the top of the dome, above every particle of theirs, which
    // a walk down from a centre never meets; the face scan seeds it.
    expect_matches_reference(dome, settings_for(0.1f, 8));
    const Extracted e = extract(dome, settings_for(0.1f, 64));
    EXPECT_LT(e.stats.peak_slices, e.grid.n + 1) << "caches released as the sweep passes";
}

TEST(MarchingSlices, WalksUpInTheUpperHalfOfABlockAndDownInTheLower) {
    // One block (n = 64): no face seeds, so the walks carry everything. Droplets of a few particles at
    // heights over the whole block; a walk heads for the nearer of the block's bottom and top faces, so
    // the upper ones are found walking up, from the droplet's top, and the lower ones walking down.
    Cloud c;
    for (int d = 0; d < 18; ++d) {
        const float x = 0.5f * float(d % 4), y = 0.5f * float(d / 4 % 4), z = 0.13f * float(d);
        c.add(x, y, z);
        if (d % 2) c.add(x + 0.08f, y, z + 0.05f), c.add(x, y + 0.07f, z - 0.04f);
    }
    const SlicesSettings s = settings_for(0.1f, 64);
    const Extracted e = extract(c, s);
    ASSERT_EQ(e.grid.blocks(), 1u);
    int upper = 0;
    for (float z : c.z) upper += SliceGrid::cell(z, e.grid.oz, e.grid.inv_voxel) * 2 > std::int32_t(e.grid.n);
    EXPECT_GE(upper, 10) << "some droplets lie in the upper half";
    EXPECT_LT(upper, 27) << "and some in the lower";
    EXPECT_GE(e.stats.seeds, 18u) << "every droplet seeded by a walk";
    expect_matches_reference(c, s);
}

TEST(MarchingSlices, FindsSmallComponentsOnCoarseGrids) {
    // Lone particles and close pairs with voxels of 1.5 and 2 radii: a component may hold a single
    // corner, and for a pair it need not be the corner nearest either centre.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> where(0.0f, 4.0f), dir(-1.0f, 1.0f);
    Cloud c;
    for (int i = 0; i < 60; ++i) {
        const float x = where(rng), y = where(rng), z = where(rng);
        c.add(x, y, z);
        if (i % 2) continue;
        float d[3] = {dir(rng), dir(rng), dir(rng)};
        const float len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) + 1e-6f;
        c.add(x + 0.2f * d[0] / len, y + 0.2f * d[1] / len, z + 0.2f * d[2] / len);
    }
    for (float voxel : {0.15f, 0.2f, 0.25f}) {
        expect_matches_reference(c, settings_for(0.1f, 8, voxel));
        expect_matches_reference(c, settings_for(0.1f, 32, voxel));
    }
}

TEST(MarchingSlices, OneParticleGivesASphereOfTheExpectedRadius) {
    Cloud c;
    c.add(0.31f, -0.12f, 0.57f);
    const float radius = 0.1f;
    const Extracted e = extract(c, settings_for(radius, 16));
    // Inside f(r) = (r^2 / (2 R_c^2) - 1/2)^2 >= iso  <=>  r <= R_c sqrt(1 - 2 sqrt(iso)).
    const double rc = 2.0 * radius, expected = rc * std::sqrt(1.0 - 2.0 * std::sqrt(double(e.iso)));
    EXPECT_NEAR(expected, 1.158 * radius, 0.01 * radius);
    ASSERT_GT(e.mesh.vertex_count, 50u);
    for (std::size_t v = 0; v < e.mesh.vertex_count; ++v) {
        const float* p = e.mesh.vertices6.data() + 6 * v;
        const double d[3] = {p[0] - 0.31, p[1] + 0.12, p[2] - 0.57};
        const double r = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        EXPECT_NEAR(r, expected, 0.1 * e.grid.voxel);
        const double dot = (d[0] * p[3] + d[1] * p[4] + d[2] * p[5]) / r;
        EXPECT_GT(dot, 0.95) << "angle-weighted normal points out";
        EXPECT_NEAR(std::sqrt(p[3] * p[3] + p[4] * p[4] + p[5] * p[5]), 1.0, 1e-5);
    }
    EXPECT_EQ(test::count_open_edges(positions_of(e.mesh), indices_of(e.mesh)), 0u);
    EXPECT_NEAR(signed_volume(e.mesh), 4.0 / 3.0 * 3.14159265 * expected * expected * expected,
                0.15 * 4.19 * expected * expected * expected);  // inscribed polyhedron
}

TEST(MarchingSlices, LatticeFacesLieOneRadiusOutside) {
    // 10^3 particles, spacing 2 R: faces at one radius outside the outermost centres, within voxel / 2.
    const float radius = 0.05f, spacing = 2 * radius;
    Cloud c;
    for (int k = 0; k < 10; ++k)
        for (int j = 0; j < 10; ++j)
            for (int i = 0; i < 10; ++i) c.add(spacing * float(i), spacing * float(j), spacing * float(k));
    for (std::uint32_t block : {8u, 16u}) {
        const Extracted e = extract(c, settings_for(radius, block));
        const float lo = -radius, hi = 9 * spacing + radius, tol = 0.5f * e.grid.voxel;
        std::size_t checked = 0;
        for (std::size_t v = 0; v < e.mesh.vertex_count; ++v) {
            const float* p = e.mesh.vertices6.data() + 6 * v;
            for (int a = 0; a < 3; ++a) {
                // Vertices over the middle of a face (away from its rounded edges).
                const int u = (a + 1) % 3, w = (a + 2) % 3;
                if (p[u] < 2 * spacing || p[u] > 7 * spacing || p[w] < 2 * spacing || p[w] > 7 * spacing)
                    continue;
                const float plane = p[a] < 4.5f * spacing ? lo : hi;
                EXPECT_NEAR(p[a], plane, tol) << "axis " << a;
                ++checked;
            }
        }
        EXPECT_GT(checked, 600u);
        EXPECT_EQ(test::count_open_edges(positions_of(e.mesh), indices_of(e.mesh)), 0u);
    }
}

TEST(MarchingSlices, SameBytesAtOneAndTwoThreadsAndSerially) {
    const Cloud c = blobs(3, 6, 300, 0.05f);
    for (const SliceField field : {SliceField::kClassic, SliceField::kSpacing}) {
        const SlicesSettings s = settings_for(0.05f, 8, 0, field);
        const std::uint64_t serial = hash_of(extract(c, s).mesh);
        for (int threads : {1, 2}) {
            ThreadControl control(threads);
            SlicesExtractor ex(s, c.size());
            SurfaceMesh mesh;
            FrameGraph graph;
            const SlicesJobIds ids = add_slices_jobs(
                graph, ex, [&c] { return c.pos(); }, [&mesh]() -> SurfaceMesh& { return mesh; });
            EXPECT_EQ(graph.job_name(ids.stage), "slices.stage");
            for (int r = 0; r < 2; ++r) {
                graph.run();
                EXPECT_EQ(hash_of(mesh), serial) << threads << " threads, run " << r;
            }
        }
    }
}

namespace {

// One worker's sweep scratch and a block's output buffers, as the extractor hands them to march_block.
struct SweepBuffers {
    SliceScratchSizes z;
    std::vector<float> slices;
    std::vector<std::uint64_t> face_bits, slice_rows, slab_rows, edge_rows, work_rows;
    std::vector<std::int32_t> slab_range, walk_lo, walk_hi;
    std::vector<std::uint32_t> edges;
    std::vector<float> positions = std::vector<float>(4 * 20000);
    std::vector<std::uint32_t> triangles = std::vector<std::uint32_t>(3 * 40000);
    std::vector<KeyedVertex> border = std::vector<KeyedVertex>(20000),
                             foreign = std::vector<KeyedVertex>(20000);

    explicit SweepBuffers(const SliceGrid& g)
        : z(g.n),
          slices(z.slices),
          face_bits(z.face_bits),
          slice_rows(z.slice_rows),
          slab_rows(z.slab_rows),
          edge_rows(z.edge_rows),
          work_rows(z.work_rows),
          slab_range(z.slab_range),
          walk_lo(z.columns),
          walk_hi(z.columns),
          edges(z.edges) {}
    SliceScratch view() {
        return {slices,    face_bits,  slice_rows, slab_rows, edge_rows,
                work_rows, slab_range, edges,      walk_lo,   walk_hi};
    }
    // Every scratch word set to `bits` (output buffers untouched).
    void fill(std::uint32_t bits) {
        auto set = [bits](auto& v) { std::memset(v.data(), int(bits & 0xff), v.size() * sizeof(v[0])); };
        set(slices), set(face_bits), set(slice_rows), set(slab_rows), set(edge_rows), set(work_rows);
        set(slab_range), set(walk_lo), set(walk_hi), set(edges);
    }
};

// What one sweep of a block gives: its vertices, its triangles and how many seeds it queued.
struct Swept {
    std::vector<float> positions;
    std::vector<std::uint32_t> triangles;
    std::uint64_t seeds = 0;
    bool operator==(const Swept&) const = default;
};

// The build of the sweep to run: march_block (AVX2 where the CPU has it) or march_block_baseline.
enum class Build { kDispatched, kBaseline };

Swept sweep_block(BlockCaches& caches, SweepBuffers& b, std::uint32_t block, const SharedFaces& shared = {},
                  Build build = Build::kDispatched) {
    const SliceGrid& g = caches.g;
    const std::uint32_t bi = block % g.bx, bj = (block / g.bx) % g.by, bk = block / (g.bx * g.by);
    const LookupCacheView cache = caches.build(bi, bj, bk);
    const SliceScratch scratch = b.view();
    const BlockMeshOut out{b.positions, b.triangles, b.border, b.foreign};
    const BlockSweepContext context{&g,      bi,  bj,    bk, caches.iso, caches.c.pos(),
                                    scratch, out, false, 0,  shared};
    const BlockSweepStats st =
        build == Build::kBaseline ? march_block_baseline(context, cache) : march_block(context, cache);
    EXPECT_FALSE(st.overflow);
    // Owned vertices from the bottom of the buffer, foreign ones from its top.
    std::vector<float> positions(b.positions.begin(), b.positions.begin() + 4 * std::ptrdiff_t(st.owned));
    positions.insert(positions.end(), b.positions.end() - 4 * std::ptrdiff_t(st.foreign), b.positions.end());
    return {positions,
            std::vector<std::uint32_t>(b.triangles.begin(),
                                       b.triangles.begin() + 3 * std::ptrdiff_t(st.triangles)),
            st.seeds};
}

// Face cells whose four corners (bit rows as SliceScratch::face_bits) are not all alike.
std::uint64_t crossed_face_cells(const std::vector<std::uint64_t>& bits, std::uint32_t n) {
    const std::uint32_t stride = row_words(n);
    auto at = [&](std::uint32_t u, std::uint32_t w) { return (bits[w * stride + u / 64] >> (u % 64)) & 1u; };
    std::uint64_t crossed = 0;
    for (std::uint32_t w = 0; w < n; ++w)
        for (std::uint32_t u = 0; u < n; ++u) {
            const auto sum = at(u, w) + at(u + 1, w) + at(u, w + 1) + at(u + 1, w + 1);
            crossed += sum != 0 && sum != 4;
        }
    return crossed;
}

}  // namespace

// A sweep's scratch needs no clearing between blocks: each block swept from zeroed scratch, then from
// scratch whose every byte is 0xff (every row bit set, every edge slot and range a bogus value): the same
// mesh.
TEST(MarchingSlices, SweepNeedsNoClearedScratch) {
    BlockCaches caches;
    SweepBuffers buf(caches.g);
    std::size_t swept = 0;
    for (std::uint32_t b = 0; b < caches.g.blocks(); ++b) {
        buf.fill(0);
        const Swept fresh = sweep_block(caches, buf, b);
        if (fresh.triangles.empty()) continue;
        buf.fill(0xff);
        EXPECT_EQ(sweep_block(caches, buf, b), fresh) << "block " << b;
        ++swept;
    }
    EXPECT_GT(swept, 3u);
}

// march_block runs an AVX2 build (eight slices per column pass in the walks, face scans and sweep) where the
// CPU has it: every block's mesh and seeds are the same bytes as the baseline build's.
TEST(MarchingSlices, Avx2AndBaselineBuildsSweepTheSameBytes) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU (or RIVULET_NO_AVX2 is set)";
    BlockCaches caches;
    SweepBuffers buf(caches.g);
    std::size_t meshed = 0;
    for (std::uint32_t b = 0; b < caches.g.blocks(); ++b) {
        const Swept avx2 = sweep_block(caches, buf, b);
        EXPECT_EQ(sweep_block(caches, buf, b, {}, Build::kBaseline), avx2) << "block " << b;
        meshed += !avx2.triangles.empty();
    }
    EXPECT_GT(meshed, 3u);
}

// A face between two blocks is scanned by the first of them and read by the other. For every pair of
// neighbouring blocks along every axis: the lower block publishes the face (its side 1) and sweeps the
// same mesh as alone; the upper block reading those bits (its side 0) sweeps the same mesh as scanning
// the face itself, and so does it when it finds the face still being scanned (it scans it itself).
// Bits that were not the face's (all clear) lose exactly that face's seeds: the upper block reads them.
TEST(MarchingSlices, AFaceScannedByOneBlockSeedsItsNeighbourAsItsOwnScan) {
    BlockCaches caches;
    const SliceGrid& g = caches.g;
    SweepBuffers buf(g);
    const std::uint32_t stride[3] = {1, g.bx, g.bx * g.by}, nb[3] = {g.bx, g.by, g.bz};
    std::vector<std::uint64_t> bits(buf.z.face_bits);
    std::size_t read = 0, seeded = 0;
    for (std::uint32_t b = 0; b < g.blocks(); ++b) {
        const std::uint32_t idx[3] = {b % g.bx, (b / g.bx) % g.by, b / (g.bx * g.by)};
        for (std::uint32_t a = 0; a < 3; ++a) {
            if (idx[a] + 1 == nb[a]) continue;
            const std::uint32_t up = b + stride[a];
            std::uint32_t state = kFaceFree;
            SharedFaces lower{}, upper{};
            lower[2 * a + 1] = upper[2 * a] = SharedFace{&state, bits.data()};
            const Swept lower_alone = sweep_block(caches, buf, b), upper_alone = sweep_block(caches, buf, up);
            std::fill(bits.begin(), bits.end(), ~std::uint64_t(0));  // publishing writes every word
            EXPECT_EQ(sweep_block(caches, buf, b, lower), lower_alone) << b << " axis " << a;
            if (state == kFaceFree) continue;  // no particle of the lower block reaches the face
            EXPECT_EQ(state, kFaceDone);
            EXPECT_EQ(sweep_block(caches, buf, up, upper), upper_alone) << up << " axis " << a;
            state = kFaceBusy;
            EXPECT_EQ(sweep_block(caches, buf, up, upper), upper_alone) << up << " axis " << a;
            EXPECT_EQ(state, kFaceBusy);
            ++read;
            // Every crossed cell of the face seeds one cube: cleared bits take exactly those seeds away.
            const std::uint64_t crossed = crossed_face_cells(bits, g.n);
            if (crossed == 0) continue;
            std::fill(bits.begin(), bits.end(), std::uint64_t(0));
            state = kFaceDone;
            EXPECT_EQ(sweep_block(caches, buf, up, upper).seeds + crossed, upper_alone.seeds) << up;
            ++seeded;
        }
    }
    EXPECT_GT(read, 10u);
    EXPECT_GT(seeded, 2u);
}

TEST(MarchingSlices, RejectsBadSettingsAndInputs) {
    SlicesSettings s;
    s.radius = -1;
    EXPECT_THROW(SlicesExtractor(s, 10), std::invalid_argument);
    s.radius = 1e-30f;  // R_c^2 underflows: every frame would be empty
    EXPECT_THROW(SlicesExtractor(s, 10), std::invalid_argument);
    s = settings_for(0.1f, 1);
    EXPECT_THROW(SlicesExtractor(s, 10), std::invalid_argument);
    s = settings_for(0.1f, 16, 1.0f);  // voxel coarser than 4 radii
    EXPECT_THROW(SlicesExtractor(s, 10), std::invalid_argument);
    s = settings_for(0.1f, 16, 0.1f / 65);  // R_c = 130 voxels: beyond the lookup cache's reach limit
    EXPECT_THROW(SlicesExtractor(s, 10), std::invalid_argument);
    s = settings_for(0.1f, 16, 0.1f / 63);  // 126 voxels: allowed
    EXPECT_NO_THROW(SlicesExtractor(s, 10));

    Cloud c;
    c.add(0, 0, 0);
    c.add(std::nanf(""), 0, 0);
    SlicesExtractor ex(settings_for(0.1f, 16), 4);
    SurfaceMesh m;
    EXPECT_THROW(ex.extract_serial(c.pos(), m), std::invalid_argument);
    Cloud many;
    for (int i = 0; i < 5; ++i) many.add(0, 0, float(i));
    EXPECT_THROW(ex.extract_serial(many.pos(), m), std::length_error);
    Cloud none;
    ex.extract_serial(none.pos(), m);
    EXPECT_EQ(m.index_count, 0u);
    // A triangle limit that is hit is reported, not silently truncated.
    SlicesSettings tight = settings_for(0.1f, 16);
    tight.max_triangles = 10;
    SlicesExtractor small(tight, 4);
    Cloud one;
    one.add(0, 0, 0);
    EXPECT_THROW(small.extract_serial(one.pos(), m), std::length_error);
    SlicesSettings few_blocks = settings_for(0.05f, 8);
    few_blocks.max_blocks = 2;
    const Cloud spread = blobs(9, 3, 10, 0.05f);
    SlicesExtractor limited(few_blocks, spread.size());
    try {
        limited.extract_serial(spread.pos(), m);
        ADD_FAILURE() << "block limit not reported";
    } catch (const std::length_error& e) {
        EXPECT_NE(std::string(e.what()).find("limit of 2"), std::string::npos) << e.what();
    }
}
