#pragma once
// A density volume (jobs/density_volume.h) as one welded triangle mesh, by marching cubes over every stored
// brick (jobs/volume_marching_cubes.h): an offline mesher and a cross-check for the other surface
// methods, not part of the per-frame graph (it allocates).
#include "jobs/density_volume.h"
#include "systems/scan/scan_mesh.h"

namespace rivulet {

// The surface F = volume.iso: each crossed lattice edge is one vertex (welded across bricks, so a closed
// surface gives a watertight mesh), normals point out of the fluid, triangles are counter-clockwise from
// outside. Bricks in slot order, each its own vertices (on its cells' edges but not those of its max faces
// that the next brick owns) then its triangles, so the bytes are the same at any thread count.
//
// Only cells of the lattice are meshed: fluid reaching the lattice's outer boundary is left open there.
// Throws std::invalid_argument when iso is not positive and finite (the space of unstored bricks, F = 0,
// must be outside) or the view's spans do not fit its grid, std::length_error past 2^32 vertices or
// indices.
TriangleMesh mesh_density_volume(const DensityVolumeView& volume);

}  // namespace rivulet
