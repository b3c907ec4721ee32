#pragma once
// What one frame of sphere scan conversion produces, living in a frame slot: the whole cylinder pool's
// vertex array (only drawn ranges are written), the draw list and the isolated particles' centres.
#include <cstdint>

#include "jobs/cylinder_layout.h"
#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"

namespace rivulet {

struct ScanOutput {
    AlignedArray<float> vertices;   // max_groups * verts_per_cylinder * 6
    AlignedArray<GroupDraw> draws;  // max_groups
    std::uint32_t draw_count = 0;
    AlignedArray<float> sphere_centers;  // 3 per particle of capacity
    std::uint32_t sphere_count = 0;
    // Counters of the frame, reported in summaries.
    std::uint32_t bin_entries = 0;
    std::uint32_t pool_exhausted = 0;
    std::uint64_t triangles = 0;

    CylinderFrameView cylinder_view() const {
        return {vertices.span(vertices.capacity()), draws.span(draw_count)};
    }
    std::span<const float> sphere_view() const { return sphere_centers.span(std::size_t(sphere_count) * 3); }
};

}  // namespace rivulet
