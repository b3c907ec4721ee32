// Taubin smoothing with a volume correction (jobs/mesh_smoothing.h): adjacency, volume kept within 1 %
// on closed slices meshes, flat water flatter, the same bytes every run.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "jobs/mesh_hash.h"
#include "jobs/mesh_smoothing.h"
#include "jobs/smoothing_weights.h"
#include "support/test_support.h"
#include "systems/slices/slices_extractor.h"

using namespace rivulet;

namespace {

struct Mesh {
    std::vector<float> v6;
    std::vector<std::uint32_t> idx;
};

Mesh slices_mesh(const std::vector<float>& x, const std::vector<float>& y, const std::vector<float>& z,
                 float radius) {
    SlicesSettings s;
    s.radius = radius;
    SlicesExtractor ex(s, x.size());
    SurfaceMesh m;
    ex.extract_serial({x, y, z}, m);
    return {{m.vertices6.data(), m.vertices6.data() + 6 * m.vertex_count},
            {m.indices.data(), m.indices.data() + m.index_count}};
}

double volume(const Mesh& m) {
    double v = 0;
    for (std::size_t t = 0; t < m.idx.size(); t += 3) {
        const float* a = &m.v6[6 * m.idx[t]];
        const float* b = &m.v6[6 * m.idx[t + 1]];
        const float* c = &m.v6[6 * m.idx[t + 2]];
        v += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) +
              double(a[1]) * (double(b[2]) * c[0] - double(b[0]) * c[2]) +
              double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
             6.0;
    }
    return v;
}

// A jittered slab of particles (top layer at z = 0) and a jittered ball apart from it.
void slab_and_ball(float radius, std::vector<float>& x, std::vector<float>& y, std::vector<float>& z) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> move(-0.3f * radius, 0.3f * radius);
    const float d = radius;  // spacing r, as users often mesh with --radius = spacing
    for (int k = 0; k < 5; ++k)
        for (int j = 0; j < 24; ++j)
            for (int i = 0; i < 24; ++i)
                x.push_back(d * float(i) + move(rng)), y.push_back(d * float(j) + move(rng)),
                    z.push_back(-d * float(k) + move(rng));
    for (int k = -4; k <= 4; ++k)
        for (int j = -4; j <= 4; ++j)
            for (int i = -4; i <= 4; ++i)
                if (i * i + j * j + k * k <= 16)
                    x.push_back(40 * radius + d * float(i) + move(rng)),
                        y.push_back(d * float(j) + move(rng)), z.push_back(d * float(k) + move(rng));
}

// Mean angle between the normal and +z over the slab's top vertices, away from its edges, in degrees.
double top_tilt(const Mesh& m, float radius) {
    double sum = 0;
    std::size_t n = 0;
    for (std::size_t v = 0; v < m.v6.size() / 6; ++v) {
        const float* p = &m.v6[6 * v];
        if (p[0] > 30 * radius || p[5] < 0.5f || p[2] < 0) continue;
        if (p[0] < 5 * radius || p[0] > 18 * radius || p[1] < 5 * radius || p[1] > 18 * radius) continue;
        sum += std::acos(std::min(1.0, double(p[5]))) * 180.0 / 3.14159265358979;
        ++n;
    }
    return n ? sum / double(n) : 180.0;
}

}  // namespace

TEST(MeshSmoothing, AdjacencyListsEachNeighbourOnceAscending) {
    const std::vector<std::uint32_t> idx = {0, 1, 2, 2, 1, 3};
    const MeshAdjacency a = mesh_adjacency(idx, 5);
    EXPECT_EQ(a.offsets, (std::vector<std::uint32_t>{0, 2, 5, 8, 10, 10}));
    EXPECT_EQ(a.neighbours, (std::vector<std::uint32_t>{1, 2, 0, 2, 3, 0, 1, 3, 1, 2}));
}

TEST(MeshSmoothing, KeepsEachComponentsVolumeAndFlattensTheOrangePeel) {
    const float radius = 0.05f;
    std::vector<float> x, y, z;
    slab_and_ball(radius, x, y, z);
    Mesh m = slices_mesh(x, y, z, radius);
    const double v0 = volume(m), tilt0 = top_tilt(m, radius);
    const std::size_t open0 = test::count_open_edges(
        [&] {
            std::vector<float> p;
            for (std::size_t v = 0; v < m.v6.size() / 6; ++v)
                p.insert(p.end(), &m.v6[6 * v], &m.v6[6 * v] + 3);
            return p;
        }(),
        m.idx);
    ASSERT_EQ(open0, 0u);
    Mesh again = m;
    const SmoothingReport r = smooth_mesh(m.v6, m.idx, 10);
    EXPECT_EQ(r.components, 2u);
    EXPECT_NEAR(volume(m) / v0, 1.0, 0.01);
    EXPECT_NEAR(r.volume_after / r.volume_before, 1.0, 0.01);
    const double tilt1 = top_tilt(m, radius);
    // 15.2 -> 10.6 degrees: Taubin keeps the particle-scale bumps of jittered data (its pass band),
    // which anisotropic kernels are for; it removes the voxel-scale ones.
    EXPECT_LT(tilt1, 0.75 * tilt0);
    for (std::size_t v = 0; v < m.v6.size() / 6; ++v)
        EXPECT_NEAR(std::hypot(m.v6[6 * v + 3], m.v6[6 * v + 4], m.v6[6 * v + 5]), 1.0, 1e-5);
    smooth_mesh(again.v6, again.idx, 10);
    EXPECT_EQ(again.v6, m.v6) << "the same bytes every run";
}

TEST(MeshSmoothing, AComponentItWouldCollapseKeepsItsVertices) {
    // A tetrahedron (outward faces): every step pulls each vertex to the others' centroid, so Taubin
    // shrinks it by about 5x in volume a pair; it is left as it was.
    Mesh m;
    const float p[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
    for (const auto& q : p) m.v6.insert(m.v6.end(), {q[0], q[1], q[2], 0, 0, 0});
    m.idx = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
    ASSERT_GT(volume(m), 0.0);
    const std::vector<float> before = m.v6;
    const SmoothingReport r = smooth_mesh(m.v6, m.idx, 3);
    EXPECT_EQ(r.components, 1u);
    EXPECT_EQ(r.kept, 1u);
    for (std::size_t v = 0; v < 4; ++v)
        for (int a = 0; a < 3; ++a) EXPECT_EQ(m.v6[6 * v + std::size_t(a)], before[6 * v + std::size_t(a)]);
    EXPECT_NEAR(r.volume_after, r.volume_before, 1e-12);
}

TEST(SmoothingWeights, FullOverTheBulkNoneOverALoneParticleAndTheyKeepSplashesInShape) {
    // A cubic lattice's own count for support 2 spacings: 1 + 6 (3/4) + 12 (1/2) + 8 (1/4) = 13.5.
    EXPECT_NEAR(lattice_neighbour_count(2.0), 13.5, 1e-12);
    const float radius = 0.05f;
    std::vector<float> x, y, z;
    slab_and_ball(radius, x, y, z);
    const float lone[3] = {-20 * radius, 5 * radius, 0};  // a droplet of one particle
    x.push_back(lone[0]), y.push_back(lone[1]), z.push_back(lone[2]);
    Mesh m = slices_mesh(x, y, z, radius);
    std::vector<float> w;
    smoothing_weights({x, y, z}, radius, m.v6, w);
    ASSERT_EQ(w.size(), m.v6.size() / 6);
    double top = 0, droplet = 0;
    std::size_t tops = 0, drops = 0;
    for (std::size_t v = 0; v < w.size(); ++v) {
        const float* p = &m.v6[6 * v];
        EXPECT_TRUE(w[v] >= 0 && w[v] <= 1) << w[v];
        if (p[0] < -10 * radius) droplet += w[v], ++drops;
        if (p[0] > 5 * radius && p[0] < 18 * radius && p[1] > 5 * radius && p[1] < 18 * radius && p[5] > 0.5f)
            top += w[v], ++tops;
    }
    ASSERT_GT(drops, 10u);
    ASSERT_GT(tops, 100u);
    EXPECT_LT(droplet / double(drops), 0.01) << "a lone particle's sphere is hardly smoothed";
    EXPECT_GT(top / double(tops), 0.3) << "the slab's top, a surface over the bulk, is";

    // 20 pairs: unweighted, the lone sphere shrinks and is pushed back out along its normals; weighted,
    // it stays where it was, and the slab's top is flattened all the same.
    Mesh weighted = m, plain = m;
    smooth_mesh(plain.v6, plain.idx, 20);
    smooth_mesh(weighted.v6, weighted.idx, 20, w);
    auto droplet_drift = [&](const Mesh& s) {
        double most = 0;
        for (std::size_t v = 0; v < s.v6.size() / 6; ++v)
            if (s.v6[6 * v] < -10 * radius)
                most = std::max(
                    most, double(std::hypot(s.v6[6 * v] - m.v6[6 * v], s.v6[6 * v + 1] - m.v6[6 * v + 1],
                                            s.v6[6 * v + 2] - m.v6[6 * v + 2])));
        return most / radius;
    };
    EXPECT_LT(droplet_drift(weighted), 0.02);
    EXPECT_GT(droplet_drift(plain), 5 * droplet_drift(weighted));
    EXPECT_LT(top_tilt(weighted, radius), 0.8 * top_tilt(m, radius));
}
