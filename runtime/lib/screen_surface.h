#pragma once
// Screen-space fluid (Janisz §3.1) as the frame pipeline's surface: the workers stage the frame's
// particle positions into the slot (screen.stage, per chunk); the render thread draws them with the
// Renderer's screen-space fluid pass. No mesh is made. With spray on, the staged particles are then split
// by their neighbour counts (jobs/spray_split.h) into the water and the spray the pass draws as sprites.
// The particles' spacing (jobs/particle_spacing.h), which sets the depth pass's spheres
// (screen_depth_radius), is measured by screen.spacing on every frame until one has kSpacingSamples
// particles or more, and kept from then on, as the slices surface's spacing field is.
#include <algorithm>

#include "jobs/particle_chunks.h"
#include "jobs/spray_split.h"
#include "runtime/lib/position_staging.h"
#include "runtime/lib/surface_system.h"
#include "systems/particles/aligned_array.h"
#include "systems/render/screen_fluid.h"

namespace rivulet {

class ScreenSurface final : public SurfaceSystem {
  public:
    // The spray jobs' chunks number at most kMaxSprayChunks per frame: every chunk keeps a row of bucket
    // counts, so their number bounds the scratch and the prefix pass.
    static constexpr std::size_t kMaxSprayChunks = 32;
    static constexpr std::uint32_t kSpacingSamples = 1024;  // particles that measure the spacing

    // `particle_radius` (the scene's) scales the spray's search distance; spray needs it to be > 0.
    // Throws std::invalid_argument on bad settings.
    ScreenSurface(const ScreenFluidSettings& settings, std::size_t max_particles, float particle_radius);

    SurfaceMethod method() const override { return SurfaceMethod::kScreen; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    // `isolated`: the particles drawn as spray.
    SurfaceStats stats(int slot) const override;
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

  private:
    // The frame's particles as add_position_staging stages them (x, y, z, count), and:
    struct Staged : StagedPositions {
        // With spray: the staged particles split, the water's [0, fluid) then the spray's [fluid, count),
        // each in particle order.
        AlignedArray<float> sx, sy, sz;
        std::size_t fluid = 0;
    };
    bool spray() const { return settings_.spray_neighbours > 0; }
    std::size_t spray_chunks(std::size_t n) const {
        return std::max<std::size_t>(spray_chunking_.count(n), 1);
    }
    // Chunk c of the staged particles the spray passes work on, and where it starts among them.
    struct SprayChunk {
        ConstPositions positions;
        std::size_t at;
    };
    SprayChunk spray_chunk(const Staged& s, std::size_t c) const;
    // The staged particles' spacing, at most 2 radii (0 where they are too few, too spread out to hash,
    // or not all finite).
    float measure_spacing(const Staged& s);
    // screen.spacing: the slot's spacing, measured until a frame of kSpacingSamples particles or more
    // gives one, then that one.
    void resolve_spacing(int slot);
    FrameGraph::JobId add_spray_jobs(FrameGraph& graph, const std::function<int()>& slot,
                                     FrameGraph::JobId after);

    ScreenFluidSettings settings_;
    std::size_t max_particles_;
    float radius_;
    std::array<Staged, kFrameSlots> staged_;
    std::array<float, kFrameSlots> spacing_{};  // per slot: FrameView::sprite_spacing
    float fixed_spacing_ = 0;
    bool spacing_fixed_ = false;
    AlignedArray<std::uint32_t> spacing_heads_, spacing_order_;  // particle_spacing's workspace
    AlignedArray<float> spacing_values_;

    // Spray scratch, shared by the slots (one frame's jobs run at a time).
    SprayGrid grid_;
    ParticleChunks spray_chunking_;
    AlignedArray<std::uint64_t> keys_;
    AlignedArray<std::uint32_t> bucket_counts_, cursors_, bucket_start_, neighbours_;
    AlignedArray<float> cell_x_, cell_y_, cell_z_;
    AlignedArray<std::uint64_t> cell_key_;
    std::array<std::uint32_t, kMaxSprayChunks> chunk_fluid_{};
};

}  // namespace rivulet
