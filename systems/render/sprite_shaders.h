#pragma once
// GLSL 4.50 sources of the diffuse-object sprite pass (systems/render/sprite_pass.h).

namespace rivulet::shaders {

// One point per particle: attribute 0 the centre and world-space diameter (xyz, size), attribute 1 the
// RGBA8 colour, normalized.
extern const char* const kDiffuseSpriteVertex;
// A soft round disc made from gl_PointCoord, premultiplied by its alpha.
extern const char* const kDiffuseSpriteFragment;

}  // namespace rivulet::shaders
