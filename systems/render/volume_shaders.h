#pragma once
// GLSL 4.50 sources of the density volume's raycast (volume_pass.h). Vertex stages are kVersion +
// kScreenCamera (screen_fluid_shaders.h) + the stage; fragment stages kFragmentPrelude (shaders.h) +
// kScreenCamera + what is listed with each.
#include <string>

namespace rivulet::shaders {

// The brick and atlas constants of jobs/density_volume.h as GLSL constants, so the two cannot drift.
std::string volume_layout_glsl();

// Empty-space skipping's first pass: the faces between blocks a ray can find the surface in and those
// it cannot, one instance each (attribute 0: block index * 8 + face, faces -x, +x, -y, +y, -z, +z; 6
// vertices; uniforms u_origin, u_block, u_blocks), into an RG32F target blended by GL_MAX (x the negated
// nearest face's eye-space depth, y the farthest's) and a depth buffer that marks the pixels they cover.
extern const char* const kVolumeShellVertex;
extern const char* const kVolumeShellFragment;
// The rays, over shaders::kFullScreenVertex: after kWaterShading and volume_layout_glsl(). Writes the
// shaded water, the hit's eye-space depth and the thickness behind it; discards misses.
extern const char* const kVolumeRaycastFragment;

}  // namespace rivulet::shaders
