#pragma once
// GLSL 4.50 sources of the screen-space fluid passes (van der Laan, Green & Sainz 2009; Janisz §3.1).
// A program is the concatenation: vertex stages kVersion + kScreenCamera + stage, fragment stages
// kFragmentPrelude (version and sky colour) + kScreenCamera + stage; full-screen passes use
// shaders::kFullScreenVertex (shaders.h).

namespace rivulet::shaders {

extern const char* const kVersion;
extern const char* const kScreenCamera;

// Particles as camera-facing triangles (instanced, 3 vertices each; attributes 0-2 read x, y, z per
// instance).
extern const char* const kSphereTriangleVertex;
// Ray-sphere intersection per pixel, shared by the two sphere passes.
extern const char* const kSphereHit;
extern const char* const kSphereDepthFragment;
extern const char* const kSphereThicknessFragment;

extern const char* const kCloseHolesFragment;
// The depth-following filter width (kFilterWidth) goes before the two filters that use it.
extern const char* const kFilterWidth;
extern const char* const kBilateralFragment;
extern const char* const kNarrowRangeFragment;
extern const char* const kCurvatureFlowFragment;
extern const char* const kThicknessBlurFragment;
extern const char* const kCompositeFragment;
// Spray: one point sprite per particle (attributes 0-2 read x, y, z per vertex), drawn after the composite.
extern const char* const kSprayVertex;
extern const char* const kSprayFragment;

}  // namespace rivulet::shaders
