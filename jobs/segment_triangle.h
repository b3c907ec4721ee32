#pragma once
// Segment against triangle (Möller–Trumbore), the per-triangle test of the particle collisions in Juckel &
// Beckhaus, "Rendering diffuse objects using particle systems inside voxelized surface geometry" (§5.2): a
// particle's positions before and after a step form the segment.
#include <optional>

#include "jobs/vec3.h"

namespace rivulet {

// Barycentric slack, in units of the triangle's own edges. Rounding alone could let a segment slip between
// two triangles that share an edge; widening every triangle by this much makes at least one of them report
// the crossing, at the price of the pair sometimes both reporting it.
inline constexpr double kSegmentTriangleSlack = 1e-7;

struct SegmentCrossing {
    double t = 0;        // along p0 -> p1, in [0, 1]
    bool front = false;  // p0 lies on the side cross(b - a, c - a) points to (outside, for outward winding)
};

// Works in double: grazing segments divide by a near-zero determinant, and float there would turn the
// barycentric slack above into a guess. Segments in the triangle's plane never cross it.
inline bool segment_crosses_triangle(Vec3f p0, Vec3f p1, Vec3f a, Vec3f b, Vec3f c, SegmentCrossing& out) {
    const double dx = double(p1.x) - p0.x, dy = double(p1.y) - p0.y, dz = double(p1.z) - p0.z;
    const double e1x = double(b.x) - a.x, e1y = double(b.y) - a.y, e1z = double(b.z) - a.z;
    const double e2x = double(c.x) - a.x, e2y = double(c.y) - a.y, e2z = double(c.z) - a.z;
    const double px = dy * e2z - dz * e2y, py = dz * e2x - dx * e2z, pz = dx * e2y - dy * e2x;
    const double det = e1x * px + e1y * py + e1z * pz;
    if (det == 0 || !std::isfinite(det)) return false;
    const double inv = 1.0 / det;
    const double sx = double(p0.x) - a.x, sy = double(p0.y) - a.y, sz = double(p0.z) - a.z;
    const double u = (sx * px + sy * py + sz * pz) * inv;
    if (u < -kSegmentTriangleSlack || u > 1 + kSegmentTriangleSlack) return false;
    const double qx = sy * e1z - sz * e1y, qy = sz * e1x - sx * e1z, qz = sx * e1y - sy * e1x;
    const double v = (dx * qx + dy * qy + dz * qz) * inv;
    if (v < -kSegmentTriangleSlack || u + v > 1 + kSegmentTriangleSlack) return false;
    const double t = (e2x * qx + e2y * qy + e2z * qz) * inv;
    if (!(t >= 0 && t <= 1)) return false;
    out.t = t;
    // det = -dot(p1 - p0, cross(e1, e2)): positive when the motion runs against the normal.
    out.front = det > 0;
    return true;
}

struct SegmentHit {
    float t = 0;   // along p0 -> p1, in [0, 1]
    Vec3f normal;  // unit cross(b - a, c - a): outward for triangles wound counter-clockwise from outside
    bool front = false;  // the segment starts on the side the normal points to
};

// Hits from either face; nullopt on a miss, for a degenerate triangle and for a segment parallel to it.
std::optional<SegmentHit> segment_triangle(Vec3f p0, Vec3f p1, Vec3f a, Vec3f b, Vec3f c);

}  // namespace rivulet
