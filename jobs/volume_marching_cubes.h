#pragma once
// Marching cubes (Lorensen & Cline, "Marching Cubes: A High Resolution 3D Surface Construction
// Algorithm", 1987) over one stored brick of a density volume (jobs/density_volume.h): every one of its
// 8^3 cells is classified with the project's tables (jobs/marching_tables.h, inside is F >= iso), each
// crossed lattice edge of the brick gets exactly one vertex, placed by linear interpolation of F to iso,
// with the normal -grad F (central differences on the lattice, interpolated along the edge like the
// position, normalised), and the triangles are counter-clockwise seen from outside the fluid.
//
// A cell reads only its brick's own 9^3 samples, so the brick is meshed from the brick alone; the
// gradient also reads the neighbouring bricks' samples one beyond each face (0 where no brick is
// stored). Lattice edges on a face between two bricks are meshed by both: the vertex on global edge
// (corner g, axis) belongs to brick_edge_owner(g, axis), the brick holding g as a cell corner, i.e. each
// brick owns the edges inside it and on its min faces (and its max faces on the lattice's outer
// boundary). Both copies of a shared sample are equal (density_volume.h), so both bricks find the same
// crossings and the owner's vertex can stand for both: the assembly (systems/volume/volume_mesh.h) welds
// the other brick's copy to it, which makes the mesh of a closed surface watertight.
#include <cstdint>
#include <span>

#include "jobs/density_volume.h"
#include "jobs/marching_tables.h"

namespace rivulet {

// Lattice edges of a brick: edge (i, j, k, axis) runs from its sample (i, j, k) one step along `axis`;
// slots exist for every sample and axis, those leaving the brick are never used.
inline constexpr std::uint32_t kBrickEdgeSlots = 3 * kBrickSamples;
inline std::uint32_t brick_edge_slot(std::uint32_t i, std::uint32_t j, std::uint32_t k, std::uint32_t axis) {
    return ((k * kBrickEdge + j) * kBrickEdge + i) * 3 + axis;
}
// Edges inside a brick (both ends among its samples): the most vertices it can have.
inline constexpr std::uint32_t kBrickMaxVertices = 3 * kBrickEdge * kBrickEdge * kBrickCells;
inline constexpr std::uint32_t kBrickMaxTriangles =
    kBrickCells * kBrickCells * kBrickCells * MarchingTables::kMaxTriangles;
// Brick-local vertex indices fit 16 bits (kBrickMaxVertices < kNoVertex), which halves what the
// assembly keeps per brick.
inline constexpr std::uint16_t kNoVertex = 0xffff;
static_assert(kBrickMaxVertices < kNoVertex && kBrickEdgeSlots <= kNoVertex);

// The brick owning global edge (gi, gj, gk, axis) (the low corner of a cell that has the edge; the last
// brick along an axis also owns its max face there) and the edge's slot in it.
struct BrickEdgeRef {
    std::uint32_t brick = 0;  // DensityGrid::brick_index
    std::uint32_t edge = 0;   // brick_edge_slot in that brick
};
inline BrickEdgeRef brick_edge_owner(const DensityGrid& grid, std::uint32_t gi, std::uint32_t gj,
                                     std::uint32_t gk, std::uint32_t axis) {
    const auto brick = [](std::uint32_t s, std::uint32_t n) {
        return s / kBrickCells < n ? s / kBrickCells : n - 1;
    };
    const std::uint32_t a = brick(gi, grid.bx), b = brick(gj, grid.by), c = brick(gk, grid.bz);
    return {grid.brick_index(a, b, c),
            brick_edge_slot(gi - a * kBrickCells, gj - b * kBrickCells, gk - c * kBrickCells, axis)};
}

// Output of one brick, in brick-local vertex indices; sizes are the capacities the spans must have. Nothing
// in them is read before the call writes it, so one set can serve brick after brick.
struct BrickMeshOut {
    std::span<float> vertices;             // 6 * kBrickMaxVertices: position, unit normal per vertex
    std::span<std::uint16_t> vertex_edge;  // kBrickMaxVertices: the brick_edge_slot of each vertex
    std::span<std::uint16_t> edge_vertex;  // kBrickEdgeSlots: the vertex on each edge, or kNoVertex
    std::span<std::uint16_t> triangles;    // 3 * kBrickMaxTriangles: vertex triples, CCW from outside
};

struct BrickMeshStats {
    // Vertices [0, owned) lie on edges the brick owns, [owned, vertices) on edges of its max faces that the
    // next brick owns; each group in order of brick_edge_slot.
    std::uint32_t vertices = 0, owned = 0;
    std::uint32_t triangles = 0;
};

// Meshes the brick stored in atlas slot `slot` (< volume.stored()). Requires volume.iso > 0 (the
// unstored space, F = 0, is then outside) and the spans of `out` at least as large as listed there
// (throws std::invalid_argument otherwise). Allocates nothing; reads only `volume`.
BrickMeshStats march_brick(const DensityVolumeView& volume, std::uint32_t slot, const BrickMeshOut& out);

}  // namespace rivulet
