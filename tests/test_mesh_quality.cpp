// The triangle-quality report of `mesh --json` (jobs/mesh_quality.h) on triangles with known angles and
// on a marching-slices mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "jobs/mesh_quality.h"
#include "systems/slices/slices_extractor.h"

using namespace rivulet;

TEST(MeshQuality, AnglesAndRadiusRatiosOfKnownTriangles) {
    // An equilateral triangle, a right isosceles one, a sliver, a degenerate one and an index out of range.
    const float h = std::sqrt(3.0f) / 2;
    const std::vector<float> v = {0, 0, 0, 1, 0, 0, 0.5f, h, 0,   // equilateral
                                  0, 0, 0, 1, 0, 0, 0,    1, 0,   // right isosceles: 45 degrees
                                  0, 0, 0, 1, 0, 0, 2,    0, 0};  // collinear
    const std::vector<std::uint32_t> idx = {0, 1, 2, 3, 4, 5, 6, 7, 8, 0, 1, 99};
    const MeshQuality q = mesh_quality(v, 3, idx);
    EXPECT_EQ(q.triangles, 4u);
    EXPECT_EQ(q.degenerate, 2u);
    EXPECT_NEAR(q.min_angle_deg, 45.0, 1e-4);
    EXPECT_NEAR(q.mean_min_angle_deg, 52.5, 1e-4);
    // Right isosceles, legs 1: R = sqrt(2) / 2, r = (2 - sqrt(2)) / 2, R / (2 r) = 1.2071.
    EXPECT_NEAR(q.max_ratio, 1.20711, 1e-4);
    EXPECT_NEAR(q.median_ratio, 1.20711, 1e-4);  // the upper of two
}

TEST(MeshQuality, ASlicesSphereIsMostlyWellShapedAndItsStatisticsAreOrdered) {
    const std::vector<float> x = {0}, y = {0}, z = {0};
    SlicesSettings s;
    s.radius = 0.1f;
    SlicesExtractor ex(s, 1);
    SurfaceMesh m;
    ex.extract_serial({x, y, z}, m);
    const MeshQuality q =
        mesh_quality({m.vertices6.data(), 6 * m.vertex_count}, 6, {m.indices.data(), m.index_count});
    EXPECT_EQ(q.triangles, m.triangle_count());
    EXPECT_GT(q.mean_min_angle_deg, 25.0);
    EXPECT_GE(q.ratio_p95, q.median_ratio);
    EXPECT_GE(q.median_ratio, 1.0);
    EXPECT_GE(q.max_ratio, q.ratio_p95);
    EXPECT_LE(q.min_angle_deg, q.min_angle_p05);
}
