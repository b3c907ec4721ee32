#include "systems/render/render_programs.h"

#include <initializer_list>
#include <string>
#include <vector>

#include "systems/render/gl_program.h"
#include "systems/render/shaders.h"

namespace rivulet {
namespace {

GLuint build(std::initializer_list<const char*> vertex, std::initializer_list<const char*> fragment,
             const std::string& name) {
    const GLuint vs = compile_shader(GL_VERTEX_SHADER, vertex, name + ".vert");
    GLuint fs = 0;
    try {
        fs = compile_shader(GL_FRAGMENT_SHADER, fragment, name + ".frag");
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    return link_program(vs, fs, name);
}

void sampler_unit(GLuint program, const char* uniform, int unit, const std::string& name) {
    glProgramUniform1i(program, uniform_location(program, uniform, name), unit);
}

}  // namespace

LitPrograms build_lit_programs() {
    // What each variant reads (the linker drops the rest): a misspelt name fails here rather than as a
    // quietly wrong picture.
    static const std::vector<const char*> kReads[shaders::kLitVariants] = {
        {"u_water_color", "u_absorption", "u_refraction", "u_scene_color", "u_scene_depth", "u_thickness",
         "u_viewport", "u_right", "u_up", "u_reflection_lod", "u_environment"},
        {"u_albedo", "u_shine", "u_shadow_map", "u_shadow_matrix", "u_shadow_texel"},
        {"u_horizon", "u_shadow_map", "u_shadow_matrix", "u_shadow_texel"},
        {"u_reflection_lod", "u_environment"},
        {"u_horizon"},
        {"u_water_color", "u_absorption", "u_refraction", "u_scene_color", "u_scene_depth", "u_slab_depth",
         "u_viewport", "u_right", "u_up", "u_reflection_lod", "u_environment"},
    };
    LitPrograms programs;
    for (int v = 0; v < shaders::kLitVariants; ++v) {
        LitProgram& p = programs[std::size_t(v)];
        const std::string name = "lit." + std::to_string(v);
        const std::string define = "#define LIT_VARIANT " + std::to_string(v) + "\n";
        p.id = build(
            {shaders::kLitVertex},
            {shaders::kFragmentPrelude, define.c_str(), shaders::kWaterShading, shaders::kLitFragment}, name);
        p.view_proj = uniform_location(p.id, "u_view_proj", name);
        p.scale = uniform_location(p.id, "u_scale", name);
        p.clip = uniform_location(p.id, "u_clip", name);
        p.eye = uniform_location(p.id, "u_eye", name);
        p.light_dir = uniform_location(p.id, "u_light_dir", name);
        for (const char* uniform : kReads[v]) uniform_location(p.id, uniform, name);
        p.water_color = glGetUniformLocation(p.id, "u_water_color");
        p.absorption = glGetUniformLocation(p.id, "u_absorption");
        p.albedo = glGetUniformLocation(p.id, "u_albedo");
        p.shine = glGetUniformLocation(p.id, "u_shine");
        p.horizon = glGetUniformLocation(p.id, "u_horizon");
        p.reflection_lod = glGetUniformLocation(p.id, "u_reflection_lod");
        p.shadow_matrix = glGetUniformLocation(p.id, "u_shadow_matrix");
        p.shadow_texel = glGetUniformLocation(p.id, "u_shadow_texel");
        p.right = glGetUniformLocation(p.id, "u_right");
        p.up = glGetUniformLocation(p.id, "u_up");
        p.viewport = glGetUniformLocation(p.id, "u_viewport");
        p.slab_depth = glGetUniformLocation(p.id, "u_slab_depth");
        p.refraction = glGetUniformLocation(p.id, "u_refraction");
        glProgramUniform1i(p.id, glGetUniformLocation(p.id, "u_scene_color"), shaders::kSceneColorUnit);
        glProgramUniform1i(p.id, glGetUniformLocation(p.id, "u_scene_depth"), shaders::kSceneDepthUnit);
        glProgramUniform1i(p.id, glGetUniformLocation(p.id, "u_thickness"), shaders::kThicknessUnit);
        glProgramUniform1i(p.id, glGetUniformLocation(p.id, "u_environment"), shaders::kEnvironmentUnit);
        glProgramUniform1i(p.id, glGetUniformLocation(p.id, "u_shadow_map"), shaders::kShadowUnit);
    }
    return programs;
}

SkyProgram build_sky_program() {
    SkyProgram p;
    p.id = build({shaders::kSkyVertex}, {shaders::kFragmentPrelude, shaders::kSkyFragment}, "sky");
    p.forward = uniform_location(p.id, "u_forward", "sky");
    p.right = uniform_location(p.id, "u_right", "sky");
    p.up = uniform_location(p.id, "u_up", "sky");
    p.half_extent = uniform_location(p.id, "u_half_extent", "sky");
    sampler_unit(p.id, "u_environment", shaders::kEnvironmentUnit, "sky");
    return p;
}

ThicknessProgram build_thickness_program() {
    ThicknessProgram p;
    const char* name = "thickness";
    p.id = build({shaders::kLitVertex}, {shaders::kMeshThicknessFragment}, name);
    p.view_proj = uniform_location(p.id, "u_view_proj", name);
    p.scale = uniform_location(p.id, "u_scale", name);
    p.clip = uniform_location(p.id, "u_clip", name);
    p.eye = uniform_location(p.id, "u_eye", name);
    return p;
}

ThicknessPointProgram build_thickness_point_program() {
    ThicknessPointProgram p;
    const char* name = "thickness_points";
    p.id = build({shaders::kSphereThicknessPointVertex}, {shaders::kSphereThicknessPointFragment}, name);
    p.view_proj = uniform_location(p.id, "u_view_proj", name);
    p.eye = uniform_location(p.id, "u_eye", name);
    p.radius = uniform_location(p.id, "u_radius", name);
    p.pixels_per_unit = uniform_location(p.id, "u_pixels_per_unit", name);
    p.max_point_size = uniform_location(p.id, "u_max_point_size", name);
    p.forward = uniform_location(p.id, "u_forward", name);
    p.right = uniform_location(p.id, "u_right", name);
    p.up = uniform_location(p.id, "u_up", name);
    p.half_extent = uniform_location(p.id, "u_half_extent", name);
    p.viewport = uniform_location(p.id, "u_viewport", name);
    return p;
}

ShadowProgram build_shadow_program() {
    ShadowProgram p;
    p.id = build({shaders::kShadowVertex}, {shaders::kShadowFragment}, "shadow");
    p.light_view_proj = uniform_location(p.id, "u_light_view_proj", "shadow");
    p.scale = uniform_location(p.id, "u_scale", "shadow");
    p.water = uniform_location(p.id, "u_water", "shadow");
    p.clip = uniform_location(p.id, "u_clip", "shadow");
    return p;
}

ShadowPointProgram build_shadow_point_program() {
    ShadowPointProgram p;
    p.id = build({shaders::kShadowPointVertex}, {shaders::kShadowPointFragment}, "shadow_points");
    p.light_view_proj = uniform_location(p.id, "u_light_view_proj", "shadow_points");
    p.point_size = uniform_location(p.id, "u_point_size", "shadow_points");
    p.depth_radius = uniform_location(p.id, "u_depth_radius", "shadow_points");
    return p;
}

}  // namespace rivulet
