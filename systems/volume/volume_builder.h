#pragma once
// The state the density-volume jobs keep between frames (jobs/density_splat.h does the work): the
// settings, the bin sort's scratch sized once for the scene, and DensityVolume, one frame's output. The
// runtime calls the member functions below as the jobs of runtime/lib/volume_jobs.h, in that order.
#include <array>
#include <cstdint>

#include "jobs/density_splat.h"
#include "jobs/particle_chunks.h"
#include "systems/particles/aligned_array.h"
#include "systems/volume/volume_settings.h"

namespace rivulet {

// One frame's volume: its grid and stored bricks (a frame slot's, or the offline mesher's).
struct DensityVolume {
    DensityGrid grid;
    float iso = 0.5f;
    std::uint32_t stored = 0;
    AlignedArray<std::int32_t> brick_slot;  // grid.bricks()
    AlignedArray<std::uint32_t> slot_brick;
    AlignedArray<float> slot_min, slot_max;
    AlignedArray<float> atlas;  // grown when a frame needs more layers, never shrunk

    DensityVolumeView view() const;
    // Of the grid, the brick table and every stored brick's samples (replay and determinism checks).
    std::uint64_t hash() const;
};

class VolumeBuilder {
  public:
    static constexpr std::size_t kMaxChunks = 16;
    static constexpr std::size_t kSplatGroups = 1;  // brick groups (jobs/density_splat.h) per splat item

    // Throws std::invalid_argument on bad settings.
    VolumeBuilder(const VolumeSettings& settings, std::size_t max_particles);
    const VolumeSettings& settings() const { return settings_; }
    // Reserves `out`'s tables for the largest grid the settings allow.
    void prepare(DensityVolume& out) const;

    // Chunks of a frame of n particles; the chunk size depends on the scene only, so the bins list
    // particles in the same order at any thread count.
    std::size_t chunks(std::size_t n) const;
    ConstPositions chunk(ConstPositions p, std::size_t c) const;

    void bounds_chunk(ConstPositions p, std::size_t c);
    // Serial: the frame's grid (throws std::invalid_argument as plan_density_grid does).
    void plan(DensityVolume& out, std::size_t n);
    void count_chunk(const DensityVolume& out, ConstPositions p, std::size_t c);
    void offsets(const DensityVolume& out, std::size_t n);
    void scatter_chunk(const DensityVolume& out, ConstPositions p, std::size_t c);
    // Serial: atlas slots for the bricks particles reach; throws std::runtime_error past max_bricks.
    void allocate(DensityVolume& out);
    std::size_t splat_items(const DensityVolume& out) const;
    // V_j from the radius (the settings), or mass / density where `volumes` gives them.
    void splat_item(DensityVolume& out, ConstPositions p, const ParticleVolumes& volumes,
                    std::size_t item) const;

  private:
    VolumeSettings settings_;
    float iso_ = 0;  // settings_.iso_value(): the calibration sums a lattice, once rather than per frame
    std::size_t max_particles_;
    ParticleChunks chunking_;
    std::size_t max_grid_bricks_ = 0, max_groups_ = 0;
    std::array<ParticleBounds, kMaxChunks> chunk_bounds_{};
    std::size_t frame_chunks_ = 0, frame_groups_ = 0, frame_row_ = 0;  // row: a chunk's table stride
    std::uint32_t splat_groups_ = 0;
    AlignedArray<std::uint32_t> counts_, cursors_, bin_start_;  // per chunk (rows of frame_row_) and group
    AlignedArray<GroupBrickMask> masks_;       // per chunk and group: the group's bricks the chunk reaches
    AlignedArray<std::uint32_t> splat_group_;  // the groups with a stored brick, in order
    AlignedArray<std::uint32_t> entries_;      // each group's particles (indices), group after group
};

}  // namespace rivulet
