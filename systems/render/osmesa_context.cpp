#include "systems/render/osmesa_context.h"

#include <stdexcept>

namespace rivulet {

OsMesaContext::OsMesaContext(int width, int height)
    : width_(width), height_(height), buffer_(std::size_t(width) * std::size_t(height) * 4u) {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           24,
                           OSMESA_STENCIL_BITS,
                           0,
                           OSMESA_ACCUM_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx_) {
        throw std::runtime_error(
            "OSMesa could not create an OpenGL 4.5 core profile context (needs Mesa with llvmpipe, and "
            "libOSMesa linked without libGL)");
    }
    try {
        make_current();
    } catch (...) {
        OSMesaDestroyContext(ctx_);
        throw;
    }
    const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    version_ = version ? version : "";
    renderer_ = renderer ? renderer : "";
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    if (major * 10 + minor < 45 || !(profile & GL_CONTEXT_CORE_PROFILE_BIT)) {
        OSMesaDestroyContext(ctx_);
        throw std::runtime_error("OSMesa gave OpenGL '" + version_ + "' (" + renderer_ +
                                 "); the renderer needs a 4.5 core profile context");
    }
}

OsMesaContext::~OsMesaContext() {
    // Unbind first so the calling thread is not left with a dangling current context.
    if (OSMesaGetCurrentContext() == ctx_) OSMesaMakeCurrent(nullptr, nullptr, 0, 0, 0);
    OSMesaDestroyContext(ctx_);
}

void OsMesaContext::make_current() {
    if (OSMesaGetCurrentContext() == ctx_) return;
    if (!OSMesaMakeCurrent(ctx_, buffer_.data(), GL_UNSIGNED_BYTE, width_, height_)) {
        throw std::runtime_error("OSMesaMakeCurrent failed for a " + std::to_string(width_) + "x" +
                                 std::to_string(height_) + " buffer");
    }
}

}  // namespace rivulet
