#include "jobs/segment_triangle.h"

namespace rivulet {

std::optional<SegmentHit> segment_triangle(Vec3f p0, Vec3f p1, Vec3f a, Vec3f b, Vec3f c) {
    SegmentCrossing x;
    if (!segment_crosses_triangle(p0, p1, a, b, c, x)) return std::nullopt;
    return SegmentHit{static_cast<float>(x.t), normalize(cross(b - a, c - a)), x.front};
}

}  // namespace rivulet
