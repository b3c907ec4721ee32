// The density volume F(r) = sum_j V_j W_poly6(r - r_j) (Inácio et al.) as the volume jobs build it:
// against a brute-force sum, a lattice's rest value, sparsity, thread-count determinism and bad input.
#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "jobs/counter_rng.h"
#include "jobs/density_splat.h"
#include "runtime/lib/frame_graph.h"
#include "runtime/lib/volume_jobs.h"
#include "support/test_support.h"
#include "systems/volume/volume_builder.h"

namespace rivulet {
namespace {

using Cloud = test::PointCloud;

// Builds the volume of `cloud` with the frame's jobs on `threads` workers (V_j from `volumes` where given).
void build(const Cloud& cloud, const VolumeSettings& s, DensityVolume& out, int threads = 2,
           ParticleVolumes volumes = {}) {
    VolumeBuilder builder(s, cloud.x.size());
    builder.prepare(out);
    FrameGraph graph;
    add_volume_jobs(
        graph, builder, [&cloud] { return cloud.pos(); }, [&out]() -> DensityVolume& { return out; }, {},
        [volumes] { return volumes; });
    tbb::task_arena arena(threads);
    arena.execute([&] { graph.run(); });
}

double brute_force(const Cloud& c, double px, double py, double pz, double h, double volume) {
    const double scale = volume * 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9));
    double f = 0;
    for (std::size_t i = 0; i < c.x.size(); ++i) {
        const double dx = c.x[i] - px, dy = c.y[i] - py, dz = c.z[i] - pz;
        const double r2 = dx * dx + dy * dy + dz * dz;
        if (r2 < h * h) f += scale * std::pow(h * h - r2, 3);
    }
    return f;
}

Cloud lattice(int n, float spacing, float offset) {
    Cloud c;
    for (int k = 0; k < n; ++k)
        for (int j = 0; j < n; ++j)
            for (int i = 0; i < n; ++i)
                c.add(offset + spacing * float(i), offset + spacing * float(j), offset + spacing * float(k));
    return c;
}

TEST(DensityVolume, LatticeInteriorIsItsRestValueAndFallsToZeroBeyondTheKernel) {
    // Spacing 2 r, h = 2.5 spacings: the poly6 lattice sum varies by under 1 % over a cell there.
    VolumeSettings s;
    s.radius = 0.5f;
    s.kernel_radii = 5.0f;
    const float spacing = 1.0f, h = s.h();
    const int n = 16;
    const Cloud c = lattice(n, spacing, 0.3f);
    DensityVolume vol;
    build(c, s, vol);
    const DensityVolumeView v = vol.view();
    // The rest value: an unbounded lattice's F at a site.
    Cloud big = lattice(9, spacing, -4.0f);
    const double rest = brute_force(big, 0, 0, 0, h, s.particle_volume());
    EXPECT_NEAR(rest, 1.0, 0.02);

    const float lo = 0.3f, hi = 0.3f + spacing * float(n - 1);
    int interior = 0, outside = 0;
    for (std::uint32_t k = 0; k < v.grid.samples_z(); ++k)
        for (std::uint32_t j = 0; j < v.grid.samples_y(); ++j)
            for (std::uint32_t i = 0; i < v.grid.samples_x(); ++i) {
                const float px = v.grid.x(i), py = v.grid.y(j), pz = v.grid.z(k);
                const float f = v.sample(i, j, k);
                // Against the direct sum everywhere.
                ASSERT_NEAR(f, brute_force(c, px, py, pz, h, s.particle_volume()), 2e-5 + 1e-5 * f)
                    << i << " " << j << " " << k;
                const auto inside_by = [&](float p) { return std::min(p - lo, hi - p); };
                const float depth = std::min({inside_by(px), inside_by(py), inside_by(pz)});
                if (depth >= h) {
                    EXPECT_NEAR(f / rest, 1.0, 0.01);
                    ++interior;
                }
                if (depth <= -h) {
                    EXPECT_EQ(f, 0.0f);
                    ++outside;
                }
            }
    EXPECT_GT(interior, 100);
    EXPECT_GT(outside, 100);
}

TEST(DensityVolume, OnlyBricksParticlesReachAreStoredAndSharedFacesAgree) {
    VolumeSettings s;
    s.radius = 0.05f;
    s.max_dim = 256;
    Cloud c;
    for (int i = 0; i < 50; ++i) c.add(0.01f * float(i % 5), 0.01f * float(i / 5 % 5), 0.01f * float(i / 25));
    for (int i = 0; i < 50; ++i) c.add(4.0f + 0.01f * float(i % 5), 3.0f, 2.0f + 0.01f * float(i / 5));
    DensityVolume vol;
    build(c, s, vol);
    const DensityVolumeView v = vol.view();
    ASSERT_GT(v.stored(), 0u);
    EXPECT_LT(v.stored() * 10, v.grid.bricks());
    // A brick between the clusters is empty and reads 0.
    const std::uint32_t mid = density_brick_of(v.grid, 2.0f, 1.5f, 1.0f);
    EXPECT_EQ(v.brick_slot[mid], -1);
    // Every sample on a face two stored bricks share has the same bits in both.
    int shared = 0;
    for (std::uint32_t s0 = 0; s0 < v.stored(); ++s0) {
        const std::uint32_t b = v.slot_brick[s0];
        const std::uint32_t a = b % v.grid.bx;
        if (a + 1 >= v.grid.bx) continue;
        const std::int32_t next = v.brick_slot[b + 1];
        if (next < 0) continue;
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
                ASSERT_EQ(v.atlas[atlas_offset(s0, kBrickCells, j, k)],
                          v.atlas[atlas_offset(std::uint32_t(next), 0, j, k)]);
                ++shared;
            }
    }
    EXPECT_GT(shared, 0);
    // The min/max table bounds every brick's samples.
    for (std::uint32_t s0 = 0; s0 < v.stored(); ++s0)
        for (std::uint32_t k = 0; k < kBrickEdge; ++k) {
            const float f = v.atlas[atlas_offset(s0, 4, 4, k)];
            EXPECT_LE(v.slot_min[s0], f);
            EXPECT_GE(v.slot_max[s0], f);
        }
}

// A box of random particles (lx x ly x lz, n of them) several brick groups long on every axis, against
// eq. 3 summed in double by scattering each particle over the lattice; and every face two stored bricks
// share has the same bits in both. With own_volumes each particle has its own volume, mass / density, the
// densities spread over 0.5-1.5 times the rest density.
void expect_direct_sums(float voxel, float lx, float ly, float lz, std::uint32_t count,
                        bool own_volumes = false) {
    VolumeSettings s;
    s.radius = 0.011f;
    s.voxel = voxel;
    s.max_dim = 512;
    Cloud c;
    for (std::uint32_t i = 0; i < count; ++i)
        c.add(lx * counter_uniform(11, 0, i, 0), ly * counter_uniform(11, 0, i, 1),
              lz * counter_uniform(11, 0, i, 2));
    std::vector<float> density(count, 0.0f);
    const float rest = 1000.0f, mass = rest * s.particle_volume();
    for (std::uint32_t i = 0; i < count; ++i) density[i] = rest * (0.5f + counter_uniform(11, 0, i, 3));
    DensityVolume vol;
    build(c, s, vol, 2, own_volumes ? ParticleVolumes{density, mass} : ParticleVolumes{});
    const DensityVolumeView v = vol.view();
    const DensityGroups groups = density_groups(v.grid);
    ASSERT_GE(groups.gx, 2u);
    ASSERT_GE(groups.gy, 2u);
    ASSERT_GE(groups.gz, 2u);

    const std::uint32_t nx = v.grid.samples_x(), ny = v.grid.samples_y(), nz = v.grid.samples_z();
    std::vector<double> direct(std::size_t(nx) * ny * nz, 0.0);
    const double h = s.h(), scale = 315.0 / (64.0 * std::numbers::pi * std::pow(h, 9));
    for (std::size_t p = 0; p < c.size(); ++p) {
        const double volume = own_volumes ? double(mass) / double(density[p]) : double(s.particle_volume());
        const auto span = [&](float x, float o, std::uint32_t n, int& lo, int& hi) {
            lo = std::max(0, int(std::floor((x - h - o) / v.grid.voxel)));
            hi = std::min(int(n) - 1, int(std::ceil((x + h - o) / v.grid.voxel)));
        };
        int i0, i1, j0, j1, k0, k1;
        span(c.x[p], v.grid.ox, nx, i0, i1), span(c.y[p], v.grid.oy, ny, j0, j1);
        span(c.z[p], v.grid.oz, nz, k0, k1);
        for (int k = k0; k <= k1; ++k)
            for (int j = j0; j <= j1; ++j)
                for (int i = i0; i <= i1; ++i) {
                    const double dx = double(v.grid.x(i)) - c.x[p], dy = double(v.grid.y(j)) - c.y[p],
                                 dz = double(v.grid.z(k)) - c.z[p];
                    const double r2 = dx * dx + dy * dy + dz * dz;
                    if (r2 < h * h)
                        direct[(std::size_t(k) * ny + j) * nx + i] +=
                            volume * scale * std::pow(h * h - r2, 3);
                }
    }
    double peak = 0;
    for (const double f : direct) peak = std::max(peak, f);
    ASSERT_GT(peak, 0.0);
    for (std::uint32_t k = 0; k < nz; ++k)
        for (std::uint32_t j = 0; j < ny; ++j)
            for (std::uint32_t i = 0; i < nx; ++i) {
                const double want = direct[(std::size_t(k) * ny + j) * nx + i];
                ASSERT_NEAR(v.sample(i, j, k), want, 1e-5 * peak) << i << " " << j << " " << k;
            }
    // Every face two stored bricks share, along each axis, has the same bits in both.
    int shared[3] = {0, 0, 0};
    for (std::uint32_t s0 = 0; s0 < v.stored(); ++s0) {
        const std::uint32_t b = v.slot_brick[s0];
        const std::uint32_t a = b % v.grid.bx, bb = b / v.grid.bx % v.grid.by,
                            cc = b / (v.grid.bx * v.grid.by);
        const std::uint32_t size[3] = {v.grid.bx, v.grid.by, v.grid.bz}, at[3] = {a, bb, cc};
        const std::uint32_t step[3] = {1, v.grid.bx, v.grid.bx * v.grid.by};
        for (int axis = 0; axis < 3; ++axis) {
            if (at[axis] + 1 >= size[axis]) continue;
            const std::int32_t next = v.brick_slot[b + step[axis]];
            if (next < 0) continue;
            for (std::uint32_t u = 0; u < kBrickEdge; ++u)
                for (std::uint32_t w = 0; w < kBrickEdge; ++w) {
                    const std::uint32_t here[3][3] = {
                        {kBrickCells, u, w}, {u, kBrickCells, w}, {u, w, kBrickCells}};
                    const std::uint32_t there[3][3] = {{0, u, w}, {u, 0, w}, {u, w, 0}};
                    const std::uint32_t* e = here[axis];
                    const std::uint32_t* f = there[axis];
                    ASSERT_EQ(v.atlas[atlas_offset(s0, e[0], e[1], e[2])],
                              v.atlas[atlas_offset(std::uint32_t(next), f[0], f[1], f[2])]);
                }
            ++shared[axis];
        }
    }
    EXPECT_GT(shared[0], 100);
    EXPECT_GT(shared[1], 100);
    EXPECT_GT(shared[2], 100);
}

TEST(DensityVolume, EverySampleIsTheDirectSumAcrossGroupsOnEveryAxis) {
    // h / voxel = 4.4: rows of eight or nine samples, one or two vectors.
    expect_direct_sums(0.01f, 3.0f, 0.3f, 0.3f, 4000);
}

TEST(DensityVolume, EachParticlesOwnVolumeWhereTheSimulationGivesMassAndDensity) {
    // V_j = mass / density_j (the SPH scenes' volumes), densities from half to one and a half the rest.
    expect_direct_sums(0.01f, 3.0f, 0.3f, 0.3f, 4000, true);
    expect_direct_sums(0.004f, 1.2f, 0.2f, 0.2f, 600, true);
}

TEST(DensityVolume, EverySampleIsTheDirectSumWhereTheKernelSpansTwoOrElevenVoxels) {
    // h / voxel = 2.2 (rows of four or five samples, a few rows a slice) and 11 (rows of 22 samples,
    // three vectors, more rows a slice than the unrolled cases).
    expect_direct_sums(0.02f, 4.0f, 0.8f, 0.8f, 3000);
    expect_direct_sums(0.004f, 1.2f, 0.2f, 0.2f, 600);
}

TEST(DensityVolume, SameBytesAtOneAndTwoThreads) {
    Cloud c;
    // More than one bin-sort chunk, spread unevenly (a dense blob and a sparse spray).
    for (std::uint32_t i = 0; i < 40000; ++i) {
        const float u = counter_uniform(7, 0, i, 0), w = counter_uniform(7, 0, i, 1),
                    t = counter_uniform(7, 0, i, 2);
        const float r = i % 4 ? 0.3f : 1.5f;
        c.add(r * (u - 0.5f), r * (w - 0.5f), r * (t - 0.5f));
    }
    VolumeSettings s;
    s.radius = 0.01f;
    DensityVolume one, two;
    build(c, s, one, 1);
    build(c, s, two, 2);
    EXPECT_GT(one.stored, 0u);
    EXPECT_EQ(one.hash(), two.hash());
}

TEST(DensityVolume, BadInputIsAClearError) {
    VolumeSettings s;
    s.radius = 0.1f;
    Cloud nan;
    nan.add(0, 0, 0), nan.add(std::nanf(""), 0, 0);
    DensityVolume vol;
    try {
        build(nan, s, vol);
        FAIL() << "NaN positions were accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("NaN"), std::string::npos) << e.what();
    }
    // An explicit voxel that needs more than --max-dim cells.
    Cloud wide;
    wide.add(0, 0, 0), wide.add(100, 0, 0);
    VolumeSettings fine = s;
    fine.voxel = 0.01f;
    try {
        build(wide, fine, vol);
        FAIL() << "a grid past --max-dim was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--max-dim"), std::string::npos) << e.what();
    }
    // The automatic voxel grows instead.
    build(wide, s, vol);
    EXPECT_LE(vol.grid.bx * kBrickCells, s.max_dim);
    VolumeSettings odd = s;
    odd.max_dim = 100;
    EXPECT_NE(odd.validate().find("--max-dim"), std::string::npos);
    odd = s;
    odd.kernel_radii = 0;
    EXPECT_FALSE(odd.validate().empty());
}

TEST(DensityVolume, CalibratedIsoPutsAFlatSurfaceOneRadiusOut) {
    // The mean F one radius above a lattice's top layer, for the default kernel, sits between the values
    // at the layer (inside) and two radii above it (outside).
    const double iso = calibrated_volume_iso(4.0);
    EXPECT_GT(iso, 0.2);
    EXPECT_LT(iso, 0.8);
}

}  // namespace
}  // namespace rivulet
