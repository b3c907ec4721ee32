// The ring-by-ring normals kernel against the definition: for every drawn triangle of the shared index
// buffer (write_cylinder_indices), add its cross product to its three corners, then normalize.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "jobs/cylinder_layout.h"
#include "jobs/cylinder_normals.h"

using namespace rivulet;

namespace {

// Rings of random radius and centre around a falling axis, poles a little above/below their rings.
std::vector<float> random_cylinder(const CylinderLayout& layout, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
    std::vector<float> v(std::size_t(layout.verts_per_cylinder()) * 6, 0.0f);
    for (std::uint32_t r = 0; r < layout.v; ++r) {
        const float y = 1.0f - 0.05f * static_cast<float>(r);
        const float cx = 0.1f * jitter(rng), cz = 0.1f * jitter(rng);
        for (std::uint32_t k = 0; k < layout.u; ++k) {
            const float theta = 6.2831853f * static_cast<float>(k) / static_cast<float>(layout.u);
            const float radius = 0.2f * (1.0f + jitter(rng));
            float* p = &v[std::size_t(layout.side_vertex(r, k)) * 6];
            p[0] = cx + radius * std::cos(theta), p[1] = y, p[2] = cz + radius * std::sin(theta);
        }
        float* top = &v[std::size_t(layout.top_pole(r)) * 6];
        float* bottom = &v[std::size_t(layout.bottom_pole(r)) * 6];
        top[0] = bottom[0] = cx, top[2] = bottom[2] = cz;
        top[1] = y + 0.03f, bottom[1] = y - 0.03f;
        // Stale normals from an earlier frame must not leak into the result.
        for (float* q : {top, bottom}) q[3] = 7.0f, q[4] = -7.0f, q[5] = 7.0f;
    }
    return v;
}

std::vector<double> reference_normals(const CylinderLayout& layout, std::uint32_t vmin, std::uint32_t vmax,
                                      const std::vector<float>& v) {
    std::vector<std::uint32_t> idx(layout.index_count());
    write_cylinder_indices(layout, idx);
    std::vector<double> n(std::size_t(layout.verts_per_cylinder()) * 3, 0.0);
    auto add_range = [&](std::size_t first, std::size_t count) {
        for (std::size_t t = first; t < first + count; t += 3) {
            const float* a = &v[std::size_t(idx[t]) * 6];
            const float* b = &v[std::size_t(idx[t + 1]) * 6];
            const float* c = &v[std::size_t(idx[t + 2]) * 6];
            const double e1[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
            const double e2[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
            const double f[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                                 e1[0] * e2[1] - e1[1] * e2[0]};
            for (int corner = 0; corner < 3; ++corner)
                for (int i = 0; i < 3; ++i) n[std::size_t(idx[t + corner]) * 3 + i] += f[i];
        }
    };
    for (std::uint32_t b = vmin; b < vmax; ++b) add_range(layout.band_index_offset(b), 6u * layout.u);
    add_range(layout.top_cap_index_offset(vmin), layout.cap_index_count());
    add_range(layout.bottom_cap_index_offset(vmax), layout.cap_index_count());
    return n;
}

void expect_matches_reference(std::uint32_t u, std::uint32_t vmin, std::uint32_t vmax, std::uint32_t seed) {
    const CylinderLayout layout{u, 12};
    std::vector<float> v = random_cylinder(layout, seed);
    const std::vector<double> ref = reference_normals(layout, vmin, vmax, v);
    cylinder_normals(layout, vmin, vmax, vmin, vmax, v);
    for (std::uint32_t r = vmin; r <= vmax; ++r) {
        for (std::uint32_t k = 0; k < layout.verts_per_ring(); ++k) {
            const std::uint32_t i = layout.ring_first_vertex(r) + k;
            const float* got = &v[std::size_t(i) * 6 + 3];
            const double* want = &ref[std::size_t(i) * 3];
            const double len = std::sqrt(want[0] * want[0] + want[1] * want[1] + want[2] * want[2]);
            if (len == 0.0) {  // an undrawn pole: defined as straight up
                EXPECT_EQ(got[0], 0.0f) << "ring " << r << " vertex " << k;
                EXPECT_EQ(got[1], 1.0f) << "ring " << r << " vertex " << k;
                EXPECT_EQ(got[2], 0.0f) << "ring " << r << " vertex " << k;
                continue;
            }
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(got[c], want[c] / len, 2e-5) << "ring " << r << " vertex " << k << " axis " << c;
        }
    }
}

}  // namespace

TEST(CylinderNormals, MatchTheAverageOfDrawnFaceNormals) {
    expect_matches_reference(20, 2, 9, 1);
    expect_matches_reference(20, 0, 11, 2);
}

TEST(CylinderNormals, OddAndSmallRingSizes) {
    expect_matches_reference(3, 1, 5, 3);
    expect_matches_reference(7, 4, 10, 4);
    expect_matches_reference(33, 0, 3, 5);
}

TEST(CylinderNormals, SingleRingGroupIsClosedByBothCaps) {
    expect_matches_reference(20, 6, 6, 6);
}

TEST(CylinderNormals, RingRangesGiveTheSameBytesAsTheWholeCylinder) {
    const CylinderLayout layout{20, 12};
    const std::vector<float> start = random_cylinder(layout, 7);
    std::vector<float> whole = start;
    cylinder_normals(layout, 1, 10, 1, 10, whole);
    for (std::uint32_t size : {1u, 2u, 3u, 4u, 9u}) {
        std::vector<float> split = start;
        // Ranges in reverse order: each reads only positions, never another range's normals.
        for (std::uint32_t first = 1 + (9 / size) * size;; first -= size) {
            if (first <= 10) cylinder_normals(layout, 1, 10, first, std::min(first + size - 1, 10u), split);
            if (first < 1 + size) break;
        }
        EXPECT_EQ(split, whole) << "ranges of " << size << " rings";
    }
}
