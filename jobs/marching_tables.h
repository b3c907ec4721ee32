#pragma once
// Marching-cubes tables, generated (not typed in) from one rule so that every case is consistent:
//
// - Corner c of a cube is at offset (c & 1, c >> 1 & 1, c >> 2 & 1); bit c of a case index is set when
//   corner c is inside (F >= iso).
// - Edge e runs along axis e / 4 from its low corner edge_corner(e, 0) to edge_corner(e, 1).
// - On each cube face the surface crosses the face boundary between inside and outside corners; every run
//   of consecutive inside corners (going round the face) is cut off by one segment. A face with two
//   diagonal inside corners therefore separates them; the rule only reads the face's own corners, so two
//   cubes sharing a face cut it identically and the surface has no cracks.
// - Segments are oriented consistently and chained into closed loops (each crossed edge lies on exactly
//   two faces); each loop is fanned into triangles, counter-clockwise seen from outside the fluid (the
//   side where F < iso), so geometric normals point out of the fluid.
#include <array>
#include <cstdint>

namespace rivulet {

struct MarchingTables {
    static constexpr int kMaxTriangles = 12;
    std::array<std::uint8_t, 256> triangle_count{};
    std::array<std::array<std::int8_t, kMaxTriangles * 3>, 256> triangles{};  // edge ids, 3 per triangle
    std::array<std::uint16_t, 256> edge_mask{};                               // bit e: edge e is crossed
    std::array<std::array<std::uint8_t, 2>, 12> edge_corner{};                // low, high corner of edge e
    std::array<std::uint8_t, 12> edge_axis{};
};

// Built once on first use (thread-safe), then read-only.
const MarchingTables& marching_tables();

}  // namespace rivulet
