// jobs/angle_normals.h: angle-weighted vertex normals (Janisz §3.2.5) against a double-precision
// reference (std::atan2 angles, exact unit face normals), degenerate triangles, and the AVX2 build against
// the baseline build byte for byte.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "jobs/angle_normals.h"
#include "jobs/cpu_dispatch.h"

namespace {

using namespace rivulet;

struct Soup {
    std::vector<float> p4;  // x, y, z, 0 per vertex
    std::vector<std::uint32_t> tri;
};

Soup random_soup(unsigned seed, std::uint32_t vertices, std::size_t triangles) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> at(-1.0f, 1.0f);
    std::uniform_int_distribution<std::uint32_t> pick(0, vertices - 1);
    Soup s;
    for (std::uint32_t v = 0; v < vertices; ++v) s.p4.insert(s.p4.end(), {at(rng), at(rng), at(rng), 0.0f});
    while (s.tri.size() < 3 * triangles) {
        const std::uint32_t a = pick(rng), b = pick(rng), c = pick(rng);
        if (a != b && b != c && a != c) s.tri.insert(s.tri.end(), {a, b, c});
    }
    return s;
}

std::vector<float> accumulate(const Soup& s, bool baseline = false) {
    std::vector<float> acc(s.p4.size(), 0.0f);
    if (baseline)
        accumulate_angle_normals_baseline(s.p4, s.tri, acc);
    else
        accumulate_angle_normals(s.p4, s.tri, acc);
    return acc;
}

// Sum over triangles of (angle at v) * (unit face normal), in double.
std::vector<std::array<double, 3>> reference(const Soup& s) {
    std::vector<std::array<double, 3>> out(s.p4.size() / 4, {0, 0, 0});
    auto pos = [&](std::uint32_t v, int c) { return double(s.p4[4 * std::size_t(v) + std::size_t(c)]); };
    for (std::size_t t = 0; t < s.tri.size(); t += 3) {
        const std::uint32_t v[3] = {s.tri[t], s.tri[t + 1], s.tri[t + 2]};
        double e1[3], e2[3], n[3];
        for (int c = 0; c < 3; ++c) e1[c] = pos(v[1], c) - pos(v[0], c), e2[c] = pos(v[2], c) - pos(v[0], c);
        n[0] = e1[1] * e2[2] - e1[2] * e2[1], n[1] = e1[2] * e2[0] - e1[0] * e2[2],
        n[2] = e1[0] * e2[1] - e1[1] * e2[0];
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (len == 0) continue;
        for (int a = 0; a < 3; ++a) {
            double u[3], w[3];
            for (int c = 0; c < 3; ++c)
                u[c] = pos(v[(a + 1) % 3], c) - pos(v[a], c), w[c] = pos(v[(a + 2) % 3], c) - pos(v[a], c);
            const double angle = std::atan2(len, u[0] * w[0] + u[1] * w[1] + u[2] * w[2]);
            for (int c = 0; c < 3; ++c) out[v[a]][std::size_t(c)] += angle * n[c] / len;
        }
    }
    return out;
}

TEST(AngleNormals, MatchADoublePrecisionReference) {
    std::vector<std::size_t> counts = {301, 2000};
    for (std::size_t t = 1; t <= 17; ++t) counts.push_back(t);  // every tail length of 4 and 8 lanes
    for (std::size_t triangles : counts) {
        const Soup s = random_soup(unsigned(triangles), 40, triangles);
        const std::vector<float> got = accumulate(s);
        const auto want = reference(s);
        std::vector<int> uses(want.size(), 0);
        for (std::uint32_t v : s.tri) ++uses[v];
        for (std::size_t v = 0; v < want.size(); ++v) {
            for (int c = 0; c < 3; ++c)  // angles within 4e-7 rad, terms at most pi: rounding per term
                EXPECT_NEAR(got[4 * v + std::size_t(c)], want[v][std::size_t(c)], 2e-6 * (uses[v] + 1))
                    << triangles << " triangles, vertex " << v;
            EXPECT_EQ(got[4 * v + 3], 0.0f);
        }
    }
}

TEST(AngleNormals, DegenerateTrianglesAddNothing) {
    Soup s = random_soup(5, 30, 100);
    const std::vector<float> clean = accumulate(s);
    // Zero-area triangles (a repeated vertex) at the front, in the middle and in the tail.
    Soup d;
    d.p4 = s.p4;
    d.tri = {3, 3, 4, 5, 6, 5};
    d.tri.insert(d.tri.end(), s.tri.begin(), s.tri.begin() + 150);
    d.tri.insert(d.tri.end(), {7, 7, 7});
    d.tri.insert(d.tri.end(), s.tri.begin() + 150, s.tri.end());
    d.tri.insert(d.tri.end(), {1, 2, 1});
    EXPECT_EQ(accumulate(d), clean);
}

TEST(AngleNormals, ClosedRegularSolidGivesNormalsAlongItsVertices) {
    // Octahedron, counter-clockwise seen from outside: every vertex normal points away from the centre.
    Soup s;
    const float v[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const auto& p : v) s.p4.insert(s.p4.end(), {p[0], p[1], p[2], 0.0f});
    s.tri = {0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5};
    const std::vector<float> acc = accumulate(s);
    for (int k = 0; k < 6; ++k) {
        float n[3] = {acc[4 * std::size_t(k)], acc[4 * std::size_t(k) + 1], acc[4 * std::size_t(k) + 2]};
        normalize_or_up(n);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(n[c], v[k][c], 1e-6f) << "vertex " << k;
    }
}

TEST(AngleNormals, Avx2AndBaselineBuildsGiveTheSameBytes) {
    if (!cpu_has_avx2()) GTEST_SKIP() << "no AVX2 on this CPU (or RIVULET_NO_AVX2 is set)";
    for (std::size_t triangles : {5u, 16u, 1001u}) {
        const Soup s = random_soup(unsigned(triangles) + 11, 60, triangles);
        EXPECT_EQ(accumulate(s), accumulate(s, true)) << triangles;
    }
}

}  // namespace
