#pragma once
// Closed, watertight meshes built in code, wound counter-clockwise seen from outside: test shapes for
// the voxelizer and the built-in "ghost" diffuse object. Every vertex is shared by all its triangles, so
// the meshes are closed by index (no seams to weld).
#include "jobs/vec3.h"
#include "systems/diffuse/colored_mesh.h"

namespace rivulet {

// `slices` around +y (>= 3), `stacks` from pole to pole (>= 2); one vertex at each pole. No colours.
ColoredMesh make_uv_sphere(Vec3f center, float radius, int slices, int stacks);
// Axis +y, tube of radius `minor` around a circle of radius `major` (minor < major); segments >= 3 each.
// No colours.
ColoredMesh make_torus(Vec3f center, float major, float minor, int major_segments, int minor_segments);
// 8 vertices, 12 triangles; min < max on every axis. No colours.
ColoredMesh make_box_mesh(Vec3f min, Vec3f max);
// A ghost about 1.6 m tall: a round head flowing into a bell-shaped body with a wavy hem, one closed
// surface of revolution (the underside vaults up inside the hem). Bottom of the hem at y = 0, centred
// on x = z = 0, facing +z. Vertex colours: pale blue-white, fading to a faint cyan glow towards the hem,
// with two dark eyes and a dark mouth on the front of the head. About 17k triangles.
ColoredMesh make_ghost_mesh();

}  // namespace rivulet
