#pragma once
// A diffuse object's particles as the frame pipeline's output (Juckel & Beckhaus, §4.4): the workers sort
// them back to front by view depth with a parallel radix sort (sprites.keys, then per 8-bit pass
// sprites.histogram / sprites.prefix / sprites.scatter) and gather them in that order into the slot
// (sprites.stage); the render thread uploads and draws the slot as point sprites. Additive scenes (fire)
// need no order and skip the sort.
#include <functional>

#include "jobs/depth_radix_sort.h"
#include "runtime/lib/surface_system.h"
#include "systems/diffuse/diffuse_simulation.h"
#include "systems/particles/aligned_array.h"

namespace rivulet {

class SpritesSurface final : public SurfaceSystem {
  public:
    static constexpr std::size_t kChunk = kDepthSortBlockSize;  // particles per staging item

    // `source` is asked on the workers for this frame's particles.
    SpritesSurface(const SceneDesc& scene, std::function<std::span<const DiffuseSprite>()> source);

    SurfaceMethod method() const override { return SurfaceMethod::kSprites; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    // `isolated`: the sprites drawn.
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    DepthSortContext sort_context(std::size_t n);

    SceneDesc scene_;
    std::function<std::span<const DiffuseSprite>()> source_;
    std::size_t max_particles_;
    struct Staged {
        AlignedArray<DiffuseSprite> sprites;
        std::size_t count = 0;
    };
    std::array<Staged, kFrameSlots> staged_;
    DepthKeyMap map_;
    std::span<const DiffuseSprite> frame_;  // the particles of the frame being sorted
    AlignedArray<std::uint32_t> keys_, keys_tmp_, order_, order_tmp_, histograms_;
};

}  // namespace rivulet
