#pragma once
// One branch of a stream (stream_skeleton.h) as a cylinder of the pool whose rings follow the stream's
// path instead of the V axis. The path is the polyline of the branch's level centroids, smoothed and
// extended to its end particles; rings sit at even arc length along it, each in the plane normal to the
// path there (so two neighbouring rings' bands form one piece with its own axis, and every joint is the
// bisecting plane of its two pieces), with frames carried along by parallel transport, so the tube
// does not twist. A ring's radii come from the spheres that cut its plane, by the seed's radial functions
// (cross_section.h); the end rings' poles close the tube one sphere beyond the end particles. A ring
// no sphere cuts takes its radii from the nearest rings that have some. The spheres find the planes they
// cut by walking the rings from their neighbour's, so the cost is about one test per cut.
#include <cstdint>
#include <span>

#include "jobs/cross_section.h"
#include "jobs/cylinder_layout.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct OrientedRingParams {
    CylinderLayout layout;
    float radius = 0;        // sphere radius
    float level_width = 0;   // the skeleton's level width (its link distance)
    float ring_spacing = 0;  // wanted arc length between rings; stretched so a branch fits layout.v rings
    CrossSectionParams section;
    AngleTable angles;  // layout.u entries
};

// Rings one sphere adds its circle to at most: rings are at least 2/3 of a radius apart along a straight
// path, so a sphere cuts three at most; more happens only where ring planes converge on the inside of a
// bend tighter than the stream, and there the first four along the path are kept.
inline constexpr std::uint32_t kMaxRingsPerSphere = 4;
// Floats of one ring's frame in the scratch (its plane, centre and the plane's two axes, four each).
inline constexpr std::uint32_t kFrameFloats = 16;
// Rings of padding around the planes in the scratch (three before, five after).
inline constexpr std::uint32_t kPlanePadding = 8;

// Scratch of one branch: `path_*` and `arc` as long as its level count + 2; the members' positions and
// cut rings as long as its members; the circles kMaxRingsPerSphere times that; ring_first layout.v + 1
// and ring_cursor layout.v.
struct RingScratch {
    std::span<float> path_x, path_y, path_z, arc, member_x, member_y, member_z, circle_x, circle_z,
        circle_rho;
    std::span<std::uint32_t> level_start;  // level count + 1
    std::span<std::uint32_t> cut_first, ring_first, ring_cursor;
    std::span<std::uint8_t> cut_count;
    std::span<float> frames;  // kFrameFloats x layout.v
    std::span<float> planes;  // 4 x (layout.v + kPlanePadding)
};

// What one branch became: its ring count (at least 2, at most layout.v), its path's length and its
// widest ring's mean radius (what tells a stream from a blob).
struct OrientedTube {
    std::uint32_t rings = 0;
    float length = 0;
    float widest = 0;
};

// `members` (particle indices) sorted by `level` (absolute levels, the first being `first_level`, `levels`
// of them). Writes the positions of rings [0, result) of `vertices` (one cylinder's block, 6 floats per
// vertex; the normal slots are used as scratch and left for cylinder_normals).
OrientedTube oriented_rings(ConstPositions p, std::span<const std::uint32_t> members,
                            std::span<const std::uint32_t> level, std::uint32_t first_level,
                            std::uint32_t levels, const OrientedRingParams& params,
                            const RingScratch& scratch, std::span<float> vertices);

}  // namespace rivulet
