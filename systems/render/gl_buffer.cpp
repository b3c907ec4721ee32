#include "systems/render/gl_buffer.h"

#include <stdexcept>
#include <string>

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

GLuint create_texture_2d(GLenum internal_format, int width, int height, GLenum filter) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glTexStorage2D(GL_TEXTURE_2D, 1, internal_format, width, height);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(filter));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(filter));
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glBindTexture(GL_TEXTURE_2D, 0);
    return t;
}

GLuint create_framebuffer(std::initializer_list<GLuint> colors, GLuint depth, const char* what) {
    GLuint f = 0;
    glGenFramebuffers(1, &f);
    glBindFramebuffer(GL_FRAMEBUFFER, f);
    GLenum buffers[8] = {};
    GLsizei count = 0;
    for (GLuint c : colors) {
        if (count == 8) break;
        buffers[count] = GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(count);
        glFramebufferTexture2D(GL_FRAMEBUFFER, buffers[count], GL_TEXTURE_2D, c, 0);
        ++count;
    }
    glDrawBuffers(count, buffers);
    if (depth) glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, depth, 0);
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE || colors.size() > 8) {
        glDeleteFramebuffers(1, &f);
        throw std::runtime_error(std::string(what) + ": a render target is incomplete (status " +
                                 std::to_string(status) + ")");
    }
    return f;
}

}  // namespace rivulet
