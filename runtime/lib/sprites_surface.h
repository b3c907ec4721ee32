#pragma once
// A diffuse object's particles as the frame pipeline's output (Juckel & Beckhaus, §4.4): the workers sort
// them back to front by view depth with a parallel radix sort over the keys the diffuse update made (per
// 8-bit pass sprites.histogram / sprites.prefix / sprites.scatter, whose last pass writes the order into
// the slot); the sprites themselves stay where the simulation wrote them (it alternates between two
// arrays, so they outlive the next frame's update). The render thread uploads both and draws the sprites
// through the order as an index buffer. Additive scenes (fire) need no order and skip the sort.
#include <functional>

#include "jobs/depth_radix_sort.h"
#include "runtime/lib/surface_system.h"
#include "systems/diffuse/diffuse_simulation.h"
#include "systems/particles/aligned_array.h"

namespace rivulet {

class SpritesSurface final : public SurfaceSystem {
  public:
    // `source` is asked on the workers for this frame's particles.
    // A frame's sprites and their sort keys, one each, as the diffuse simulation made them.
    struct SpriteSource {
        std::span<const DiffuseSprite> sprites;
        std::span<const std::uint32_t> depth_keys;
    };
    SpritesSurface(const SceneDesc& scene, std::function<SpriteSource()> source);

    SurfaceMethod method() const override { return SurfaceMethod::kSprites; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    // `isolated`: the sprites drawn.
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    DepthSortContext sort_context(std::size_t n, int slot);

    SceneDesc scene_;
    std::function<SpriteSource()> source_;
    std::size_t max_particles_;
    // The frame's sprites as the simulation left them and, unless additive, their back-to-front order:
    // the renderer draws through the order, so the sort never gathers the 20-byte sprites.
    struct Staged {
        std::span<const DiffuseSprite> sprites;
        AlignedArray<std::uint32_t> order;
    };
    bool sorted() const { return !scene_.diffuse.additive; }
    // The slot's back-to-front order; empty for additive sprites.
    std::span<const std::uint32_t> order(int slot) const;
    std::array<Staged, kFrameSlots> staged_;
    SpriteSource frame_;  // the particles of the frame being sorted
    AlignedArray<std::uint32_t> keys_tmp_, order_tmp_, histograms_;
};

}  // namespace rivulet
