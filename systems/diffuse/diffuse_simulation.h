#pragma once
// A diffuse object alive across frames (Juckel & Beckhaus, "Rendering diffuse objects using particle
// systems inside voxelized surface geometry"): its voxels, its particles' attributes beside the
// ParticleSet, the density per voxel and the colliders. Each frame runs begin_frame (serial: where the
// object and colliders are, which voxels colliders block), then the phases of kPhases in order:
//   update        parallel over update blocks: ages, forces, moves; the dead marked
//   compact       serial: the voxel changes counted; the dead listed
//   emit_count    parallel over emit blocks: how many each emitting voxel adds
//   emit_offsets  serial: where each block's new particles go (the dead's places first); which live
//                 particle from the end fills each place no birth takes
//   compact_fill  parallel over fill blocks: those particles copied into the places
//   emit          parallel over emit blocks: the new particles (the next update sets their
//                 interpolation state from their voxel: DiffuseUpdateContext::born)
// The frame graph runs each phase as one job named by kPhases (runtime/lib/simulation_jobs.cpp), a serial
// step as run_phases_serial. Everything is sized at construction; a frame allocates nothing.
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "jobs/diffuse_emit.h"
#include "jobs/diffuse_update.h"
#include "systems/diffuse/solid_collider.h"
#include "systems/diffuse/voxel_object.h"
#include "systems/particles/aligned_array.h"
#include "systems/particles/particle_set.h"
#include "systems/scenes/scene.h"

namespace rivulet {

struct DiffusePhase {
    const char* job;  // the frame graph's job
    bool parallel;    // runs for each of its blocks (any order, any thread), else once
};

class DiffuseSimulation {
  public:
    enum Phase : std::size_t {
        kUpdate = 0,
        kCompact,
        kEmitCount,
        kEmitOffsets,
        kCompactFill,
        kEmit,
        kPhaseCount
    };
    static constexpr std::array<DiffusePhase, kPhaseCount> kPhases = {{{"diffuse.update", true},
                                                                       {"diffuse.compact", false},
                                                                       {"diffuse.emit_count", true},
                                                                       {"diffuse.emit_offsets", false},
                                                                       {"diffuse.compact_fill", true},
                                                                       {"diffuse.emit", true}}};

    // Loads and voxelizes the scene's mesh, builds the colliders; `particles` gets the capacity.
    // Throws std::invalid_argument / std::runtime_error on a bad mesh or attributes.
    DiffuseSimulation(const SceneDesc& scene, ParticleSet& particles);
    ~DiffuseSimulation();

    // `offset`: the object's displacement from its rest pose at the end of this frame (FrameInputs).
    void begin_frame(ParticleSet& particles, std::uint64_t frame, Vec3f offset);
    // Blocks of `phase` as it starts (the update's depend on how many particles live); 1 when serial.
    std::size_t phase_blocks(std::size_t phase, const ParticleSet& particles) const;
    // Every block of a phase finishes before the next phase starts.
    void run_phase(std::size_t phase, std::size_t block, ParticleSet& particles);
    // After begin_frame: every phase, each block in turn, on this thread.
    void run_phases_serial(ParticleSet& particles);

    // What the sprite pass draws of the frame: one sprite for each particle the update stepped, in the
    // order it stepped them, final once the update's blocks are done (kSprites: the sort can run beside
    // the rest of the frame). The dead among them are transparent; the births join the next frame's,
    // since a particle is born transparent; so the copies and births that close the gaps need not touch
    // the sprites. Frames alternate between kSpriteBuffers arrays, so a frame's sprites stay as they are
    // while the next frame is simulated (the frame pipeline draws frame N from them while the workers
    // make N + 1): no copy to hand over.
    static constexpr int kSpriteBuffers = 2;
    static constexpr Phase kSprites = kUpdate;
    std::span<const DiffuseSprite> sprites() const;
    // Each sprite's back-to-front sort key (diffuse_depth_map), made by the update.
    std::span<const std::uint32_t> depth_keys() const;
    DiffuseAttributeSpans attributes(std::size_t n);
    const VoxelObject& object() const { return object_; }
    const DiffuseGrid& grid() const { return grid_; }
    std::span<const std::uint32_t> density() const { return density_; }
    // Whether voxel v is inside the mesh and switched off by a collider this frame.
    bool blocked(std::uint32_t v) const {
        return object_.material[v] != kNoMaterial && column_[v] == object_.materials.size();
    }
    // World-space centre of collider c at the end of the last begun frame.
    Vec3f collider_centre(std::size_t c) const { return steps_[c].offset1; }
    std::size_t collider_count() const { return steps_.size(); }
    const SolidCollider& collider(std::size_t c) const { return colliders_[c]; }
    Vec3f object_offset() const { return offset_; }

  private:
    std::size_t update_blocks(const ParticleSet& particles) const;
    void update_block(std::size_t block, ParticleSet& particles);
    void compact(ParticleSet& particles);
    std::size_t fill_blocks() const;
    void fill_block(std::size_t block, ParticleSet& particles);
    std::size_t emit_blocks() const { return emit_counts_.size(); }
    void emit_count_block(std::size_t block, ParticleSet& particles);
    void emit_offsets(ParticleSet& particles);
    void emit_block(std::size_t block, ParticleSet& particles);
    DiffuseUpdateContext update_context(ParticleSet& particles);
    DiffuseEmitContext emit_context(ParticleSet& particles);
    void block_voxels();

    SceneDesc scene_;
    VoxelObject object_;
    DiffuseGrid grid_;
    std::vector<float> step_table_;  // the materials' steps and, last, the outside's: no force, no drag
    std::vector<std::uint32_t> density_;
    std::vector<std::uint16_t> column_;  // diffuse_voxel_column of every voxel: colliders switch them off
    std::vector<SolidCollider> colliders_;
    std::vector<DiffuseColliderStep> steps_;
    std::vector<std::array<int, 6>> blocked_ranges_;  // voxel box each collider blocked last frame
    AlignedArray<std::uint32_t> voxel_, from_rgba_, to_rgba_;
    AlignedArray<float> from_size_, to_size_, elapsed_, duration_;
    std::array<AlignedArray<DiffuseSprite>, kSpriteBuffers> sprite_;
    int sprite_buffer_ = 0;    // this frame's
    std::size_t sprites_ = 0;  // this frame's: the particles it began with
    AlignedArray<std::uint32_t> depth_key_;
    DepthKeyMap depth_map_;
    std::vector<std::uint32_t> dead_, dead_count_, dead_all_;
    std::vector<std::uint32_t> born_;   // the last frame's births, ascending, for the update to finish
    std::vector<std::uint32_t> fills_;  // (from, to) pairs: the live particle that fills each dead place
    std::vector<std::uint32_t> moves_, move_count_;  // voxel changes per update block
    std::vector<std::uint32_t> emit_counts_, emit_offsets_;
    std::size_t compact_from_ = 0;     // the count before this frame's compaction
    std::size_t births_in_place_ = 0;  // this frame's births that take a dead one's place
    std::size_t emit_first_ = 0;       // where the births beyond those go
    std::uint32_t next_id_ = 0, birth_first_id_ = 0;
    std::uint64_t frame_ = 0;
    Vec3f offset_, prev_offset_, velocity_;
    DissolveFront dissolve_;
    bool first_frame_ = true;
};

// Where collider c of `desc` is at time t (seconds): eased from `from` to `to` and back every period.
Vec3f diffuse_collider_position(const DiffuseCollider& c, double t);

// The sprites' sort keys for the scene's (fixed) camera: depth along its view over a window 8 m deep
// around its target; 16-bit keys are 0.12 mm apart.
DepthKeyMap diffuse_depth_map(const CameraDesc& camera);

}  // namespace rivulet
