#pragma once
// Meshes to solid coloured voxels: the voxel space of a diffuse object ("Rendering diffuse objects using
// particle systems inside voxelized surface geometry", Juckel & Beckhaus, §4.2). A voxel is inside when
// its centre is inside the closed mesh (parity of crossings along +x, jobs/voxelize_columns.h, exact for
// rays through shared edges and vertices) and takes the colour of the surface nearest to it, as the
// paper's voxels take the model's colour where the slicing meets it.
//
// The mesh must be watertight: after welding vertices with identical positions, every undirected edge
// of a non-degenerate triangle must be used by exactly two triangles. Several closed shells are fine as
// long as they do not intersect (a shell inside another one carves a cavity; shells that cross each
// other leave their overlap outside). Orientation is not needed.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "jobs/vec3.h"
#include "systems/diffuse/colored_mesh.h"

namespace rivulet {

struct VoxelGridShape {
    int nx = 0, ny = 0, nz = 0;
    Vec3f origin;  // min corner of voxel (0, 0, 0)
    float cell = 1;
    std::size_t count() const { return std::size_t(nx) * ny * nz; }
    std::size_t index(int ix, int iy, int iz) const { return (std::size_t(iz) * ny + iy) * nx + ix; }
    // Centre of voxel (ix, iy, iz).
    Vec3f centre(int ix, int iy, int iz) const {
        return origin +
               Vec3f{(float(ix) + 0.5f) * cell, (float(iy) + 0.5f) * cell, (float(iz) + 0.5f) * cell};
    }
};

struct SolidVoxels {
    VoxelGridShape shape;
    std::vector<std::uint8_t> inside;  // shape.count(): 1 inside, 0 outside
    // Colour of the nearest surface point for inside voxels (0 outside); white when the mesh has no
    // colours.
    std::vector<float> r, g, b;
    std::size_t inside_count() const;
};

inline constexpr int kMaxVoxelResolution = 256;
inline constexpr int kMaxVoxelPadding = 64;
inline constexpr std::size_t kMaxVoxelizeTriangles = 50'000'000;

// Cubic cells: the longest axis of the mesh's bounding box spans `resolution` voxels, the other axes
// the fewest whole voxels that cover the mesh; the grid starts at the bounding box's min corner, and
// `padding` empty voxels surround it on every side. The voxel colour of an inside voxel near the surface
// (within one cell) is the mesh colour interpolated at the closest point of the closest triangle; deeper
// voxels take the colour of the nearest such voxel (an exact Euclidean distance transform).
//
// Throws std::invalid_argument for resolution outside [1, 256], padding outside [0, 64], an empty mesh,
// more than 50 M triangles, a size that is not a multiple of 3, a colour array of the wrong size, a
// vertex index out of range, a non-finite coordinate, a mesh with no extent, or an open mesh (the
// message counts the edges that bound holes and the edges shared by more than two triangles).
// Deterministic: the same bytes at any thread count.
SolidVoxels voxelize(const ColoredMesh& mesh, int resolution, int padding = 1);

}  // namespace rivulet
