#include "systems/render/gl_buffer.h"

namespace rivulet {
namespace {

void attribute(GLuint index, GLuint binding, GLuint offset) {
    glEnableVertexAttribArray(index);
    glVertexAttribFormat(index, 3, GL_FLOAT, GL_FALSE, offset);
    glVertexAttribBinding(index, binding);
}

}  // namespace

GLuint create_buffer() {
    GLuint id = 0;
    glGenBuffers(1, &id);
    glBindBuffer(GL_COPY_WRITE_BUFFER, id);  // a generated name becomes a buffer object on first bind
    return id;
}

void buffer_data(GLuint buffer, std::size_t bytes, const void* data, GLenum usage) {
    glBindBuffer(GL_COPY_WRITE_BUFFER, buffer);
    glBufferData(GL_COPY_WRITE_BUFFER, static_cast<GLsizeiptr>(bytes), data, usage);
}

void buffer_sub_data(GLuint buffer, std::size_t offset, std::size_t bytes, const void* data) {
    glBindBuffer(GL_COPY_WRITE_BUFFER, buffer);
    glBufferSubData(GL_COPY_WRITE_BUFFER, static_cast<GLintptr>(offset), static_cast<GLsizeiptr>(bytes),
                    data);
}

void GrowingBuffer::upload(const void* data, std::size_t bytes) {
    if (bytes == 0) return;
    if (bytes > capacity) {
        // Headroom so a slowly growing mesh does not respecify the storage every frame.
        capacity = bytes + bytes / 2;
        buffer_data(id, capacity, nullptr, GL_DYNAMIC_DRAW);
    }
    buffer_sub_data(id, 0, bytes, data);
}

GLuint create_mesh_vao(GLuint vbo, GLuint ibo) {
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glBindVertexBuffer(0, vbo, 0, 6 * sizeof(float));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    attribute(0, 0, 0);
    attribute(1, 0, 3 * sizeof(float));
    glBindVertexArray(0);
    return vao;
}

GLuint create_instanced_sphere_vao(GLuint vbo, GLuint ibo, GLuint instance_vbo) {
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glBindVertexBuffer(0, vbo, 0, 3 * sizeof(float));
    glBindVertexBuffer(1, instance_vbo, 0, 3 * sizeof(float));
    glVertexBindingDivisor(1, 1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
    attribute(0, 0, 0);
    attribute(1, 0, 0);
    attribute(2, 1, 0);
    glBindVertexArray(0);
    return vao;
}

}  // namespace rivulet
