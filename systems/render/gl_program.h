#pragma once
// Shader compile/link with the driver's info log in the exception text, and GL error checks for setup.
#include <initializer_list>
#include <string_view>

#include "systems/render/gl.h"

namespace rivulet {

// Compiles the concatenation of `sources` (e.g. a shared prelude, then the stage's main). Throws
// std::runtime_error naming `name` and carrying the info log on failure.
GLuint compile_shader(GLenum stage, std::initializer_list<const char*> sources, std::string_view name);

// Links and then deletes the two shaders. Throws std::runtime_error with the info log on failure.
GLuint link_program(GLuint vertex_shader, GLuint fragment_shader, std::string_view name);

// Location of a uniform the program must have; throws when the linker dropped or never saw it, which
// otherwise shows up only as a silently wrong picture.
GLint uniform_location(GLuint program, const char* uniform, std::string_view program_name);

// Throws std::runtime_error naming `what` if GL has recorded an error since the last check.
void check_gl(std::string_view what);

}  // namespace rivulet
