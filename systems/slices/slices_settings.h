#pragma once
// Parameters of marching slices (seed 004 §3.2) and how the particle radius maps onto the field.
//
//   R_c = rc_factor * radius                (default rc_factor 2: neighbours one diameter apart blend)
//   iso = calibrated_iso(rc_factor)         when iso <= 0 (the default): the mean field one radius above
//                                           the top layer of a cubic lattice of spacing 2 * radius, so a
//                                           flat fluid surface lies about one radius outside the outermost
//                                           particle centres (for rc_factor 2: iso = 0.1105, and a lone
//                                           particle gives a sphere of radius 1.158 * radius)
//   voxel = radius / 2                      when voxel <= 0
#include <cstdint>
#include <string>

namespace rivulet {

struct SlicesSettings {
    float radius = 0.02f;                      // particle radius, world units
    float voxel = 0;                           // cube edge; <= 0: radius / 2
    std::uint32_t block_cubes = 40;            // n: a block is n^3 cubes
    float rc_factor = 2.0f;                    // R_c / radius
    float iso = 0;                             // threshold on F; <= 0: calibrated_iso(rc_factor)
    std::uint32_t max_blocks = 1u << 20;       // non-empty blocks a frame may have
    std::uint64_t max_triangles = 1ull << 26;  // triangles a frame may have
    std::uint32_t max_grid_cubes = 1u << 20;   // cubes along any axis
    // Seed from every z column too: finds empty cavities (bubbles enclosing no particle) that the
    // heuristic and the face scan can miss, at the cost of evaluating every corner (docs/marching_slices.md).
    bool exhaustive_seeds = false;

    float voxel_size() const { return voxel > 0 ? voxel : 0.5f * radius; }
    float rc() const { return rc_factor * radius; }
    float iso_value() const;
    // Empty when valid, else what is wrong.
    std::string validate() const;
};

// F one unit above the top layer of a semi-infinite cubic lattice of spacing 2 (radius 1, R_c =
// rc_factor), averaged over 8 x 8 points of a lattice cell.
double calibrated_iso(double rc_factor);

}  // namespace rivulet
