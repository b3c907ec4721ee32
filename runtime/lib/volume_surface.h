#pragma once
// The density volume (Inácio et al., "Interactive Simulation and Visualization of Fluids with Surface
// Raycasting") as the frame pipeline's surface: the workers build the frame's sparse volume into the slot
// (runtime/lib/volume_jobs.h) and stage the particle centres for the key light's shadow (volume.stage);
// the render thread uploads the volume and raycasts its iso-surface (systems/render/volume_pass.h). No
// mesh is made.
#include <utility>

#include "runtime/lib/position_staging.h"
#include "runtime/lib/surface_system.h"
#include "systems/render/volume_pass.h"
#include "systems/volume/volume_builder.h"

namespace rivulet {

class VolumeSurface final : public SurfaceSystem {
  public:
    // Throws std::invalid_argument on bad settings.
    VolumeSurface(const VolumeSettings& settings, const VolumeRaycastSettings& raycast,
                  std::size_t max_particles);

    SurfaceMethod method() const override { return SurfaceMethod::kVolume; }
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<int()> slot, FrameGraph::JobId after) override;
    void use_particle_volumes(std::function<ParticleVolumes()> volumes) override {
        volumes_ = std::move(volumes);
    }
    // `groups`: stored bricks.
    SurfaceStats stats(int slot) const override;
    // The volume's (DensityVolume::hash); the staged centres only cast shadows.
    std::uint64_t output_hash(int slot) const override;
    void prepare_renderer(Renderer& renderer) const override;
    void fill_view(int slot, FrameView& view) const override;

    const DensityVolume& volume(int slot) const { return volume_[slot]; }

  private:
    VolumeBuilder builder_;
    std::function<ParticleVolumes()> volumes_;  // none: V from the radius
    VolumeRaycastSettings raycast_;
    std::size_t max_particles_;
    std::array<DensityVolume, kFrameSlots> volume_;
    std::array<StagedPositions, kFrameSlots> staged_;
};

}  // namespace rivulet
