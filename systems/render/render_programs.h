#pragma once
// The renderer's two linked programs with their uniform locations looked up once.
#include "systems/render/gl.h"

namespace rivulet {

struct LitProgram {
    GLuint id = 0;
    GLint view_proj = -1, scale = -1, eye = -1, light_dir = -1, material = -1;
};

struct SkyProgram {
    GLuint id = 0;
    GLint forward = -1, right = -1, up = -1, half_extent = -1;
};

// Both throw std::runtime_error with the compiler/linker log on failure.
LitProgram build_lit_program();
SkyProgram build_sky_program();

}  // namespace rivulet
