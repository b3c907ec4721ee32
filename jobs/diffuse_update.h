#pragma once
// One step of a diffuse object's particles (Juckel & Beckhaus, "Rendering diffuse objects using particle
// systems inside voxelized surface geometry", §4.3, §5): each particle moves by the force of the voxel it
// is in, bounces off the colliders it crosses, looks up its new voxel, and on entering one starts
// interpolating towards that voxel's colour and size; outside the active voxels it fades by its last
// voxel's fading attributes and dies when faded. A voxel whose targets are the particle's own (the same
// material and colour) is no new target: the particle keeps interpolating as it was. A kernel is (block,
// context); it runs eight particles to a vector (four without AVX2), the motion and the lookups in lanes, and
// falls back to one particle at a time only where a lane meets a collider's box or changes voxel. Either
// build gives the bits of apply_voxel_step and of the other build.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/diffuse_particles.h"
#include "jobs/diffuse_step_table.h"
#include "jobs/particle_spans.h"

namespace rivulet {

// A collider during this step: its offsets at the step's start and end (it moves in between), the world
// box its surface sweeps, and its collision test in its own frame (a SolidCollider behind `solid`).
struct DiffuseColliderStep {
    const void* solid = nullptr;
    bool (*collide)(const void* solid, Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) = nullptr;
    Vec3f offset0, offset1;
    Vec3f swept_min, swept_max;
    // In the collider's frame, a ball every colliding step enters (SolidCollider::reach_*): the update's
    // lanes skip the collision test for steps that pass it by.
    Vec3f reach_centre;
    float reach_radius = 3.0e38f;
};

struct DiffuseUpdateContext {
    ParticleSpans particles;
    DiffuseAttributeSpans attributes;
    DiffuseGrid grid;
    Vec3f offset;  // the object's displacement this step (object space = world - offset)
    std::span<const std::uint16_t> material;  // per voxel
    std::span<const std::uint32_t> voxel_rgba;
    std::span<const VoxelMaterial> materials;
    // Per voxel: its column of `steps` (diffuse_voxel_column), which also says whether it is active.
    std::span<const std::uint16_t> column;
    std::span<std::uint32_t> density;  // per voxel; diffuse_apply_moves brings it up to date
    std::span<const DiffuseColliderStep> colliders;
    Vec3f accel;  // the scene's gravity or wind, everywhere
    DissolveFront dissolve;
    DepthKeyMap depth_map;  // the sprites' sort keys, made here while the positions are at hand
    // make_diffuse_step_table(materials, the step outside the active voxels: no force, no drag)
    std::span<const float> steps;
    float restitution = 0.3f;
    float dt = 1.0f / 60.0f;
    std::size_t block_size = 16384;
    // Each block lists its particles that died this step, ascending: dead[b * block_size + k].
    std::span<std::uint32_t> dead;
    std::span<std::uint32_t> dead_count;  // per block
    // Each block lists the voxel changes of its particles, (from, to) pairs with kOutsideVoxel for no
    // active voxel: moves[2 * (b * block_size + k)]. The counts are applied after the update, not with
    // atomic adds during it: a count's cache line would travel between the cores on every change.
    std::span<std::uint32_t> moves;
    std::span<std::uint32_t> move_count;  // per block
    // The particles born since the last step, ascending: the emission leaves their interpolation state to
    // the update, which sets it from their voxel as it steps them (born transparent, fading in to the
    // voxel's colour and size over its interpolation time). Their cache lines are then on the way in
    // anyway, where the emission would have fetched them only to write.
    std::span<const std::uint32_t> born;
};

// A voxel's column of the step table: its material while it has one and no collider overlaps it, else
// the outside's (the last, `materials`). One lookup per particle instead of the material and the flag.
inline std::uint16_t diffuse_voxel_column(std::uint16_t material, bool blocked, std::size_t materials) {
    return material != kNoMaterial && !blocked ? material : static_cast<std::uint16_t>(materials);
}

inline std::size_t diffuse_update_blocks(std::size_t particles, std::size_t block_size) {
    return (particles + block_size - 1) / block_size;
}

void diffuse_update_block(std::size_t block, const DiffuseUpdateContext& ctx);

// After every block's update: each block's moves applied to the density, in block order (integer adds,
// so the counts are the same whatever order the blocks ran in).
void diffuse_apply_moves(const DiffuseUpdateContext& ctx, std::size_t blocks);

// Fills the holes the dead leave with live particles from the end, in a fixed order (O(dead)); returns
// the new count. `move(from, to)` copies every array of particle `from` to `to`.
template <class Move>
std::size_t fill_dead_from_end(std::size_t count, std::span<const std::uint32_t> dead_ascending,
                               Move&& move) {
    std::size_t lo = 0, hi = dead_ascending.size(), end = count;
    while (lo < hi) {
        if (dead_ascending[hi - 1] == end - 1) {
            --hi, --end;
            continue;
        }
        move(end - 1, dead_ascending[lo]);
        ++lo, --end;
    }
    return end;
}

}  // namespace rivulet
