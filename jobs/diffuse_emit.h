#pragma once
// Emission of a diffuse object (Juckel & Beckhaus, "Rendering diffuse objects using particle systems
// inside voxelized surface geometry", §4.3): every active voxel below its maximum density gets new
// particles, which take their attributes from the voxel rather than from an emitter. In a fixed order:
// per-block counts, a serial prefix, then each block writes its particles at its offset, so the particles
// and their ids are the same whatever thread runs which block. The frame's births take the places of its
// dead first (lowest place first), then go after the live ones: where births match deaths no particle has
// to be moved to close the gaps. A birth writes no sprite: born transparent, it is first drawn by the next
// frame's update (DiffuseSimulation::sprites).
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/diffuse_particles.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct DiffuseEmitContext {
    std::span<const std::uint32_t> inside;  // voxels inside the mesh, ascending
    std::span<const std::uint16_t> material;
    std::span<const std::uint32_t> voxel_rgba;
    std::span<const VoxelMaterial> materials;
    // Per voxel: its step-table column (diffuse_voxel_column); an inside voxel has the outside's,
    // materials.size(), only while a collider overlaps it.
    std::span<const std::uint16_t> column;
    std::span<std::uint32_t> density;
    DiffuseGrid grid;
    Vec3f offset;           // the object's displacement (world = object space + offset)
    Vec3f object_velocity;  // the object's motion, given to new particles as momentum (§5.1)
    DissolveFront dissolve;
    std::size_t block_size = 4096;
    std::span<std::uint32_t> counts;   // per block: wanted, then (after the prefix) granted
    std::span<std::uint32_t> offsets;  // per block
    ParticleSpans particles;           // every place a new particle may take
    DiffuseAttributeSpans attributes;
    // Birth k (in emission order) goes to places[k], or to first + k - places.size() past them.
    std::span<const std::uint32_t> places;
    std::size_t first = 0;
    std::uint32_t first_id = 0;  // birth k's id is first_id + k
    std::uint64_t seed = 0, frame = 0;
};

inline std::size_t diffuse_emit_blocks(std::size_t inside, std::size_t block_size) {
    return (inside + block_size - 1) / block_size;
}
void diffuse_emit_count_block(std::size_t block, const DiffuseEmitContext& ctx);
// Serial: offsets from the counts, granting blocks in order until `room` particles are granted; returns
// the number of particles the frame emits.
std::size_t diffuse_emit_offsets(const DiffuseEmitContext& ctx, std::size_t room);
void diffuse_emit_block(std::size_t block, const DiffuseEmitContext& ctx);

}  // namespace rivulet
