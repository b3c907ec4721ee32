#pragma once
// Diffuse objects' particles as soft round point sprites ("Rendering diffuse objects using particle
// systems inside voxelized surface geometry", Juckel & Beckhaus, §4.4): blended back to front with
// premultiplied-alpha "over", or added for emissive effects such as fire. Runs on the render thread,
// inside the Renderer's GL context; draws into whichever framebuffer is bound, tested against its depth
// without writing it.
#include <cstdint>
#include <memory>

#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"

namespace rivulet {

class SpritePass {
  public:
    // In the current context: the program and a vertex buffer for `max_sprites` sprites, sized once.
    // `width` and `height` are the picture's, in pixels (sprite sizes follow its height).
    SpritePass(std::uint32_t max_sprites, int width, int height);
    ~SpritePass();  // in the context it was made in
    SpritePass(const SpritePass&) = delete;
    SpritePass& operator=(const SpritePass&) = delete;

    void set_camera(const CameraDesc& camera);
    // Uploads the live sprites (in the order given, which is the drawing order) and draws them; nothing
    // when there are none. Throws std::out_of_range for more than max_sprites(). Leaves the GL state it
    // touches (blending, depth test and mask, point size, program, vertex array) as it found it.
    void draw(const DiffuseSpritesView& view);
    std::uint32_t max_sprites() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rivulet
