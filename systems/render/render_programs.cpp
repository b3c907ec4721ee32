#include "systems/render/render_programs.h"

#include "systems/render/gl_program.h"
#include "systems/render/shaders.h"

namespace rivulet {

LitProgram build_lit_program() {
    LitProgram p;
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, {shaders::kLitVertex}, "lit.vert");
    GLuint fs = 0;
    try {
        fs = compile_shader(GL_FRAGMENT_SHADER, {shaders::kFragmentPrelude, shaders::kLitFragment},
                            "lit.frag");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    p.id = link_program(vs, fs, "lit");
    p.view_proj = uniform_location(p.id, "u_view_proj", "lit");
    p.scale = uniform_location(p.id, "u_scale", "lit");
    p.eye = uniform_location(p.id, "u_eye", "lit");
    p.light_dir = uniform_location(p.id, "u_light_dir", "lit");
    p.material = uniform_location(p.id, "u_material", "lit");
    return p;
}

SkyProgram build_sky_program() {
    SkyProgram p;
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, {shaders::kSkyVertex}, "sky.vert");
    GLuint fs = 0;
    try {
        fs = compile_shader(GL_FRAGMENT_SHADER, {shaders::kFragmentPrelude, shaders::kSkyFragment},
                            "sky.frag");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    p.id = link_program(vs, fs, "sky");
    p.forward = uniform_location(p.id, "u_forward", "sky");
    p.right = uniform_location(p.id, "u_right", "sky");
    p.up = uniform_location(p.id, "u_up", "sky");
    p.half_extent = uniform_location(p.id, "u_half_extent", "sky");
    return p;
}

}  // namespace rivulet
