#pragma once
// GLSL 4.50 sources. The analytic sky colour lives in a shared prelude for passes without a cube map;
// the renderer's own passes sample the environment cube map (environment_map.h), so the background and
// every reflection agree.

namespace rivulet::shaders {

// "#version" line and the analytic sky colour, prepended to every fragment shader.
extern const char* const kFragmentPrelude;

// Lit geometry. Attributes: 0 position, 1 normal, 2 per-instance offset (constant when not instancing:
// zero, or the tank's displacement). Uniforms: u_view_proj, u_scale, u_clip (x0, z0, x1, z1: the box
// gl_ClipDistance 0-3 keep, when enabled), u_eye, u_light_dir, u_environment (cube map, unit
// kEnvironmentUnit), and per variant: water, kWaterShading's uniforms, u_right and u_up (the camera's
// axes), u_viewport, u_thickness (unit kThicknessUnit; the pool variant reads u_slab_depth instead, the
// depth it absorbs over); u_albedo and u_shine (solids), u_horizon (ground), u_reflection_lod (water, glass),
// u_shadow_map (depth comparison, unit kShadowUnit), u_shadow_matrix and u_shadow_texel (solids and the
// near ground). The water variants need kWaterShading between the prelude and kLitFragment. The
// fragment shader is compiled once per kLit* variant below, with "#define LIT_VARIANT n" after the prelude:
// llvmpipe runs both sides of every branch for every pixel, so one program per material keeps the lookups a
// material does not need off its pixels. Glass comes out with alpha for blending; everything else is opaque.
extern const char* const kLitVertex;
extern const char* const kLitFragment;

// shade_water() and its uniforms (u_water_color, u_absorption, u_refraction, u_scene_color,
// u_scene_depth; the lit programs read the last two from units kSceneColorUnit and kSceneDepthUnit),
// water_fresnel(cos theta) and water_window_depth(d, near_far): the water every method shows, placed
// between the prelude and a fragment shader's main.
extern const char* const kWaterShading;
// The fluid surfaces' thickness (kLitVertex's outputs; uniform u_eye) into a signed sum
// and a depth span, then resolved into one thickness per pixel over kFullScreenVertex (u_signed_sum,
// u_span): see shaders.cpp and thickness_targets.h.
extern const char* const kMeshThicknessFragment;
// The isolated spheres' share of it as round points (attributes 0-2 the centre's x, y, z); uniforms
// u_view_proj, u_eye, u_radius, u_pixels_per_unit, u_max_point_size, u_forward, u_right, u_up,
// u_half_extent, u_viewport.
extern const char* const kSphereThicknessPointVertex;
extern const char* const kSphereThicknessPointFragment;
extern const char* const kThicknessResolveFragment;

// A triangle covering the target, from gl_VertexID (3 vertices, no attributes), at window depth 1.
extern const char* const kFullScreenVertex;

// Full-screen sky from gl_VertexID (3 vertices, no attributes), sampling u_environment. Uniforms:
// u_forward, u_right, u_up, u_half_extent (tan of the half field of view, x and y).
extern const char* const kSkyVertex;
extern const char* const kSkyFragment;

// Shadow casters as triangles: attribute 0 position, 2 offset (as kLitVertex); u_light_view_proj, u_scale,
// u_clip (as kLitVertex), u_water (water casts a half shadow, kShadowFragment).
extern const char* const kShadowVertex;
// Shadow casters as round points (screen-space fluid particles): attributes 0, 1, 2 the centre's x, y, z
// (one float each, the particles' arrays as they are); u_light_view_proj, u_point_size (pixels),
// u_depth_radius (the radius in window depth units).
extern const char* const kShadowPointVertex;
extern const char* const kShadowFragment;
extern const char* const kShadowPointFragment;

// shade_water's u_refraction: how far the scene behind the water shifts, in texture coordinates, per
// unit of the normal's screen part and of thickness (capped at 0.2), for every method alike.
inline constexpr float kRefraction = 0.25f;

inline constexpr int kLitWater = 0;
inline constexpr int kLitSolid = 1;  // colliders, the pool rim, the SPH tank's frame
inline constexpr int kLitGround = 2;
inline constexpr int kLitGlass = 3;      // the SPH tank's walls
inline constexpr int kLitGroundFar = 4;  // the ground beyond the shadow map's reach: no lookups
inline constexpr int kLitPool = 5;       // water over the pool's depth, not a measured thickness
inline constexpr int kLitVariants = 6;

// Texture units the renderer's programs read; the screen-space fluid pass uses 0-3 for its own targets
// and reads the same environment on 4.
inline constexpr int kEnvironmentUnit = 4;
inline constexpr int kShadowUnit = 5;
// The lit water's refraction source (the picture before the water, its colour and depth) and the
// fluid's thickness.
inline constexpr int kSceneColorUnit = 6;
inline constexpr int kThicknessUnit = 7;
inline constexpr int kSceneDepthUnit = 8;

}  // namespace rivulet::shaders
