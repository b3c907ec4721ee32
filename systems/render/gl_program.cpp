#include "systems/render/gl_program.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

namespace rivulet {
namespace {

std::string info_log(GLuint object, bool is_program) {
    GLint length = 0;
    if (is_program) {
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    } else {
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    }
    std::string log(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
    if (is_program) {
        glGetProgramInfoLog(object, static_cast<GLsizei>(log.size()), nullptr, log.data());
    } else {
        glGetShaderInfoLog(object, static_cast<GLsizei>(log.size()), nullptr, log.data());
    }
    log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
    return log;
}

}  // namespace

GLuint compile_shader(GLenum stage, std::initializer_list<const char*> sources, std::string_view name) {
    const GLuint shader = glCreateShader(stage);
    if (!shader) throw std::runtime_error("glCreateShader failed for shader '" + std::string(name) + "'");
    const std::vector<const char*> texts(sources);
    glShaderSource(shader, static_cast<GLsizei>(texts.size()), texts.data(), nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        const std::string log = info_log(shader, false);
        glDeleteShader(shader);
        throw std::runtime_error("compiling shader '" + std::string(name) + "' failed:\n" + log);
    }
    return shader;
}

GLuint link_program(GLuint vertex_shader, GLuint fragment_shader, std::string_view name) {
    const GLuint program = glCreateProgram();
    glAttachShader(program, vertex_shader);
    glAttachShader(program, fragment_shader);
    glLinkProgram(program);
    glDeleteShader(vertex_shader);
    glDeleteShader(fragment_shader);
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        const std::string log = info_log(program, true);
        glDeleteProgram(program);
        throw std::runtime_error("linking program '" + std::string(name) + "' failed:\n" + log);
    }
    return program;
}

GLint uniform_location(GLuint program, const char* uniform, std::string_view program_name) {
    const GLint location = glGetUniformLocation(program, uniform);
    if (location < 0) {
        throw std::runtime_error("program '" + std::string(program_name) + "' has no active uniform '" +
                                 uniform + "'");
    }
    return location;
}

void check_gl(std::string_view what) {
    const GLenum error = glGetError();
    if (error == GL_NO_ERROR) return;
    // GL queues one flag per kind of error; drain them so the next check reports only new ones.
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
    }
    throw std::runtime_error("OpenGL error 0x" + [&] {
        char hex[16];
        std::snprintf(hex, sizeof hex, "%04X", static_cast<unsigned>(error));
        return std::string(hex);
    }() + " during " + std::string(what));
}

}  // namespace rivulet
