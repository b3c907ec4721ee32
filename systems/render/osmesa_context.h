#pragma once
// An OSMesa OpenGL 4.5 core context drawing into its own RGBA8 buffer. Current on one thread at a time:
// make_current() binds it to the calling thread.
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "systems/render/gl.h"

namespace rivulet {

class OsMesaContext {
  public:
    // Creates the context and makes it current on the calling thread. Throws std::runtime_error when
    // OSMesa cannot give a 4.5 core context.
    OsMesaContext(int width, int height);
    ~OsMesaContext();
    OsMesaContext(const OsMesaContext&) = delete;
    OsMesaContext& operator=(const OsMesaContext&) = delete;

    // Cheap when already current on this thread.
    void make_current();

    int width() const { return width_; }
    int height() const { return height_; }
    // Colour buffer, RGBA8, rows bottom to top; holds the picture once glFinish has returned.
    std::span<const std::uint8_t> pixels() const { return buffer_; }
    const std::string& version() const { return version_; }
    const std::string& renderer() const { return renderer_; }

  private:
    int width_, height_;
    std::vector<std::uint8_t> buffer_;
    OSMesaContext ctx_ = nullptr;
    std::string version_, renderer_;
};

}  // namespace rivulet
