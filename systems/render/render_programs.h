#pragma once
// The renderer's linked programs with their uniform locations looked up once.
#include <array>

#include "systems/render/gl.h"
#include "systems/render/shaders.h"

namespace rivulet {

// One variant of the lit program (shaders::kLit*). Locations a variant does not use are -1, which
// glProgramUniform* ignores, so every variant can be given every uniform.
struct LitProgram {
    GLuint id = 0;
    GLint view_proj = -1, scale = -1, clip = -1, eye = -1, light_dir = -1, reflection_lod = -1;
    GLint water_color = -1, absorption = -1, albedo = -1, shine = -1, horizon = -1;
    GLint shadow_matrix = -1, shadow_texel = -1;
    GLint right = -1, up = -1, viewport = -1, slab_depth = -1, refraction = -1;
};
using LitPrograms = std::array<LitProgram, shaders::kLitVariants>;

struct SkyProgram {
    GLuint id = 0;
    GLint forward = -1, right = -1, up = -1, half_extent = -1;
};

// The fluid surfaces' thickness (shaders::kMeshThicknessFragment) over kLitVertex.
struct ThicknessProgram {
    GLuint id = 0;
    GLint view_proj = -1, scale = -1, clip = -1, eye = -1;
};

struct ThicknessPointProgram {
    GLuint id = 0;
    GLint view_proj = -1, eye = -1, radius = -1, pixels_per_unit = -1, max_point_size = -1, forward = -1,
          right = -1, up = -1, half_extent = -1, viewport = -1;
};

// Depth only, from the key light: triangles (u_scale and the offset attribute as the lit program) and
// round points for the screen-space fluid's particles.
struct ShadowProgram {
    GLuint id = 0;
    GLint light_view_proj = -1, scale = -1, clip = -1, water = -1;
};
struct ShadowPointProgram {
    GLuint id = 0;
    GLint light_view_proj = -1, point_size = -1, depth_radius = -1;
};

// All throw std::runtime_error with the compiler/linker log on failure. The lit and sky programs read
// the environment on shaders::kEnvironmentUnit and the shadow map on shaders::kShadowUnit; lit water
// reads the scene behind on kSceneColorUnit and the thickness on kThicknessUnit.
LitPrograms build_lit_programs();
SkyProgram build_sky_program();
ThicknessProgram build_thickness_program();
ThicknessPointProgram build_thickness_point_program();
ShadowProgram build_shadow_program();
ShadowPointProgram build_shadow_point_program();

}  // namespace rivulet
