#pragma once
// Fixed topology of one pre-tessellated cylinder (Hoetzlein & Höllerer 2009 §2.1). Every cylinder of the pool
// shares it; only vertex positions change per frame, so the index buffer is built and sent to GL once.
//
// Rings are cross-section planes along V, ring 0 at the top (largest y). Ring r holds U side vertices,
// then a top pole and a bottom pole (used only when r is the first/last ring of a group: the caps that
// close the tube). Vertices of rings [vmin, vmax] are therefore one contiguous range.
//
// Index buffer (triangles, counter-clockwise seen from outside):
//   bands   b = 0 .. V-2 : 2U triangles joining ring b and ring b+1
//   top caps  r = 0 .. V-1 : U triangles fan from the top pole of ring r
//   bottom caps r = 0 .. V-1 : U triangles fan from the bottom pole of ring r
// A group spanning [vmin, vmax] draws bands [vmin, vmax-1], top cap vmin and bottom cap vmax: closed.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rivulet {

struct CylinderLayout {
    std::uint32_t u = 20;   // vertices around a ring
    std::uint32_t v = 120;  // rings along the V axis

    std::uint32_t verts_per_ring() const { return u + 2; }
    std::uint32_t verts_per_cylinder() const { return v * verts_per_ring(); }
    std::uint32_t ring_first_vertex(std::uint32_t ring) const { return ring * verts_per_ring(); }
    std::uint32_t side_vertex(std::uint32_t ring, std::uint32_t k) const {
        return ring * verts_per_ring() + k;
    }
    std::uint32_t top_pole(std::uint32_t ring) const { return ring * verts_per_ring() + u; }
    std::uint32_t bottom_pole(std::uint32_t ring) const { return ring * verts_per_ring() + u + 1; }

    std::size_t band_index_offset(std::uint32_t band) const { return std::size_t(band) * 6u * u; }
    std::size_t top_cap_index_offset(std::uint32_t ring) const {
        return std::size_t(v - 1) * 6u * u + std::size_t(ring) * 3u * u;
    }
    std::size_t bottom_cap_index_offset(std::uint32_t ring) const {
        return std::size_t(v - 1) * 6u * u + std::size_t(v) * 3u * u + std::size_t(ring) * 3u * u;
    }
    std::size_t cap_index_count() const { return 3u * std::size_t(u); }
    std::size_t index_count() const { return std::size_t(v - 1) * 6u * u + 2u * std::size_t(v) * 3u * u; }
};

// Fills `out` (size layout.index_count()) with the shared cylinder topology.
void write_cylinder_indices(const CylinderLayout& layout, std::span<std::uint32_t> out);

// One drawn group: cylinder `cylinder` of the pool, rings [vmin, vmax] inclusive.
struct GroupDraw {
    std::uint32_t cylinder = 0;
    std::uint32_t vmin = 0;
    std::uint32_t vmax = 0;
};

}  // namespace rivulet
