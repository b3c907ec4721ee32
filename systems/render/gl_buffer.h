#pragma once
// Small GL object helpers shared by the renderer's draw paths. libOSMesa exports no direct-state-access
// entry points (glNamedBufferData and friends do not link), so these bind explicitly.
#include <cstddef>
#include <initializer_list>

#include "systems/render/gl.h"

namespace rivulet {

GLuint create_buffer();
// Both go through GL_COPY_WRITE_BUFFER: binding GL_ELEMENT_ARRAY_BUFFER would change whichever VAO is
// bound, and GL_ARRAY_BUFFER is easy to leave pointing somewhere unexpected.
void buffer_data(GLuint buffer, std::size_t bytes, const void* data, GLenum usage);
void buffer_sub_data(GLuint buffer, std::size_t offset, std::size_t bytes, const void* data);

// A buffer whose storage only grows: frames reuse it, so steady-state uploads never reallocate.
struct GrowingBuffer {
    GLuint id = 0;
    std::size_t capacity = 0;  // bytes

    void create() { id = create_buffer(); }
    // Copies `bytes` to offset 0, respecifying the storage (larger, with headroom) when it does not fit.
    void upload(const void* data, std::size_t bytes);
};

// A 2D texture of one level, clamped at its edges, filtered by `filter` (GL_NEAREST or GL_LINEAR).
GLuint create_texture_2d(GLenum internal_format, int width, int height, GLenum filter);
// A framebuffer with `colors` as attachments 0, 1, ... (all drawn to) and `depth` (0: none). Throws
// std::runtime_error naming `what` when GL finds it incomplete.
GLuint create_framebuffer(std::initializer_list<GLuint> colors, GLuint depth, const char* what);

// Vertex array reading interleaved position/normal (6 floats) from `vbo` and indices from `ibo`.
// Attribute 2 (instance offset) stays disabled, so it reads the constant (0, 0, 0).
GLuint create_mesh_vao(GLuint vbo, GLuint ibo);

// Vertex array for a unit sphere: position and normal both read the 3 floats per vertex of `vbo`, and
// attribute 2 reads one xyz offset per instance from `instance_vbo`.
GLuint create_instanced_sphere_vao(GLuint vbo, GLuint ibo, GLuint instance_vbo);

}  // namespace rivulet
