#pragma once
// GLSL 4.50 sources. The sky colour function lives in a shared prelude so that the background and the
// water's reflection agree.

namespace rivulet::shaders {

// "#version" line and the sky colour, prepended to every fragment shader.
extern const char* const kFragmentPrelude;

// Lit geometry. Attributes: 0 position, 1 normal, 2 per-instance offset (constant zero when not
// instancing). Uniforms: u_view_proj, u_scale, u_eye, u_light_dir, u_material (kMaterial* below).
extern const char* const kLitVertex;
extern const char* const kLitFragment;

// Full-screen sky from gl_VertexID (3 vertices, no attributes). Uniforms: u_forward, u_right, u_up,
// u_half_extent (tan of the half field of view, x and y).
extern const char* const kSkyVertex;
extern const char* const kSkyFragment;

inline constexpr int kMaterialWater = 0;
inline constexpr int kMaterialCollider = 1;
inline constexpr int kMaterialGround = 2;

}  // namespace rivulet::shaders
