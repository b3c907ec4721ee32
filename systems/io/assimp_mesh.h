#pragma once
// Coloured triangle meshes from any format Assimp reads (OBJ, PLY, glTF / GLB, FBX, ...): the input of
// diffuse objects (systems/diffuse/voxelizer.h).
#include <string>

#include "systems/diffuse/colored_mesh.h"

namespace rivulet {

// Every mesh of the scene, with its node transforms applied, merged into one mesh of triangles (polygons
// are triangulated; points and lines dropped; identical vertices joined within each mesh). Colour per
// vertex, from the first source that a mesh has:
//   1. vertex colour channel 0 (alpha dropped);
//   2. the material's diffuse (or base colour) texture at the vertex's UV channel 0, times the diffuse
//      colour, when the texture is embedded (uncompressed, or PNG) or a PNG file beside the model;
//   3. the material's diffuse (or base colour) colour, unless the material is one Assimp invents for
//      files without materials (named "DefaultMaterial", or unnamed).
// When no mesh of the file has any, colors is empty; when some do, the others are white. Colours are
// clamped to [0, 1].
// Throws std::runtime_error naming the path when the file is missing or Assimp cannot read it (with
// Assimp's message), when it has no triangles, more than 50 M triangles, or a non-finite coordinate.
ColoredMesh read_colored_mesh(const std::string& path);

}  // namespace rivulet
