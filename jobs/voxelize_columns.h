#pragma once
// Solid voxelization by the parity of ray crossings, one slab of columns at a time: the kernel behind
// diffuse objects ("Rendering diffuse objects using particle systems inside voxelized surface geometry",
// Juckel & Beckhaus, §4.2, which slices the model on the GPU; this is the same inside test done exactly
// on the CPU). Columns run along +x through voxel centres; a voxel is inside when the ray from -x
// crosses the surface an odd number of times before its centre.
//
// Exactness: vertices come in grid space (voxel centre (ix, iy, iz) at (ix, iy, iz)) as fixed point
// integers with kColumnFixedBits fraction bits, so every 2D edge function in the (y, z) projection is an
// exact 64-bit integer. A column that passes exactly through an edge or a vertex is decided by simulation
// of simplicity: the column is taken as displaced by (+e, +e^2) in (y, z) for an infinitesimal e, which
// puts it strictly inside exactly one triangle of every fan it would otherwise graze. So a closed mesh
// gives every column an even number of crossings, and a column through a shared edge or vertex counts
// one crossing there, never 0 or 2 (a silhouette edge, where the surface folds back, counts 0 or 2).
// Triangles with zero projected area are never crossed.
//
// A crossing at x = t flips the voxels whose centre lies at or beyond t (ix >= t): as if the centre were
// displaced towards +x as well. So with the column rule, a voxel centre exactly on the surface counts as
// lying an infinitesimal step towards (+x, +y, +z): a box whose faces pass through voxel centres keeps the
// centres in [min, max) on every axis.
#include <cstddef>
#include <cstdint>
#include <span>

namespace rivulet {

// Fraction bits of the fixed point grid coordinates. Grid coordinates stay within +-2^9 (the driver's
// grids are at most 384 voxels a side), so they fit 24 bits and products of differences fit 52.
inline constexpr int kColumnFixedBits = 14;
inline constexpr int kColumnMaxGrid = 512;

// Columns are grouped into square tiles of `tile` x `tile` columns in (y, z); tile (ty, tz) has the
// triangles whose projected bounds meet it. A slab is one row of tiles: tz, every ty.
struct VoxelizeColumnsContext {
    int nx = 0, ny = 0, nz = 0;
    int tile = 8;
    int tiles_y = 0, tiles_z = 0;
    std::span<const std::int32_t> fixed;            // xyz per vertex, grid space * 2^kColumnFixedBits
    std::span<const std::uint32_t> indices;         // three per triangle
    std::span<const std::uint32_t> tile_start;      // tiles_y * tiles_z + 1 offsets into tile_triangles
    std::span<const std::uint32_t> tile_triangles;  // per tile, ascending triangle numbers
    std::span<std::uint8_t> inside;                 // nx * ny * nz, x fastest: 1 inside, 0 outside
};

// Column (iy, iz) range of a triangle's projected bounds: the columns whose centre can be covered.
// Empty (lo > hi) when none is. Shared by the binning and the kernel so both agree.
struct ColumnBounds {
    int y0, y1, z0, z1;
};
ColumnBounds triangle_columns(const std::int32_t* a, const std::int32_t* b, const std::int32_t* c, int ny,
                              int nz);

// Writes inside[] of every column of slab tz (rows iz in [tz * tile, min(nz, tz * tile + tile))).
// Touches no other memory; needs no scratch.
void voxelize_columns(int tz, const VoxelizeColumnsContext& ctx);

}  // namespace rivulet
