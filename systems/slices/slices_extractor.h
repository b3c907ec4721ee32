#pragma once
// Marching slices as a system (Janisz §3.2): owns the per-block buffers (block lists, lookup caches,
// sweep scratch, per-block meshes), grown rarely, and exposes the per-frame jobs the frame graph runs:
//
//   begin_frame                      bounds, block grid; anisotropic: the neighbour hash    (serial)
//   shape(chunk)*                    anisotropic kernels only: smoothed centres and kernel shapes
//                                    (jobs/anisotropic_kernels.h); the jobs below then place the
//                                    smoothed centres
//   block_count(chunk)* -> block_prefix -> block_scatter(chunk)*   particles into blocks (jobs/block_bins.h)
//   extract_block(block)*            lookup cache + seeds + sweep per non-empty block
//                                    (jobs/lookup_cache.h, jobs/marching_slices.h)
//   weld_offsets                     vertex / triangle offsets per block, limits (serial)
//   weld_block(block)*               indices remapped to global (border vertices to their owner block's
//                                    copy)
//   normals_block(block)*            angle-weighted normal sums per block (jobs/angle_normals.h)
//   borders                          border vertices' normal sums added to their owners', in block order
//                                    (serial)
//   stage(block)*                    the block's owned vertices out: position and normalised normal
//   (* = independent items, run in parallel)
//
// Ownership rule: the vertex on global edge (corner g, axis a) belongs to the block holding cube g, i.e.
// each block owns the vertices on its min faces; a block that also produced it (on its max faces) refers
// to the owner's copy. Both compute it from the same corner values summed in the same global order, so
// the welded mesh is watertight across block borders. Output is in block order: the same bytes at any
// thread count.
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "jobs/anisotropic_kernels.h"
#include "jobs/cell_hash.h"
#include "jobs/lookup_cache.h"
#include "jobs/marching_slices.h"
#include "jobs/particle_chunks.h"
#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"
#include "systems/particles/aligned_array.h"
#include "systems/slices/slices_settings.h"
#include "systems/slices/surface_mesh.h"

namespace rivulet {

struct SlicesStats {
    std::uint32_t blocks = 0;         // blocks of the grid
    std::uint32_t active_blocks = 0;  // blocks holding particles
    std::uint64_t block_entries = 0;  // particle-in-block listings
    std::uint64_t seeds = 0, cubes = 0, slice_fills = 0;
    std::uint32_t peak_slices = 0;  // most slice caches one block held at once
    std::uint64_t vertices = 0, triangles = 0;
};

class SlicesExtractor {
  public:
    static constexpr ParticleChunks kChunks{};  // the block sort's chunks

    // Throws std::invalid_argument when settings.validate() fails.
    SlicesExtractor(const SlicesSettings& settings, std::size_t max_particles);
    ~SlicesExtractor();
    SlicesExtractor(const SlicesExtractor&) = delete;
    SlicesExtractor& operator=(const SlicesExtractor&) = delete;

    static constexpr std::uint32_t kSpacingSamples = 1024;  // particles that measure the spacing

    const SlicesSettings& settings() const { return settings_; }
    // The field's R_c, iso and the spacing they were calibrated for; the spacing field measures the data
    // at the first frame of at least kSpacingSamples particles and keeps that for later frames (a
    // sequence's surface does not breathe with the estimate); smaller frames before it are measured each
    // for itself. Until the first non-empty frame rc() is the widest R_c the settings allow.
    const SliceFieldValues& field() const { return field_; }
    // Measures the spacing again at the next frame (the spacing field without a set spacing): for callers
    // whose frames are unrelated, so that each surface depends on its own particles only.
    void forget_field() {
        field_resolved_ = settings_.field == SliceField::kClassic || settings_.spacing > 0;
    }
    float rc() const { return rc_; }
    float iso() const { return iso_; }
    float voxel() const { return voxel_; }
    const SliceGrid& grid() const { return grid_; }
    // Anisotropic kernels: the last frame's smoothed centres and kernel shapes, one per particle.
    ConstPositions kernel_centres() const {
        return {centre_x_.span(particles_), centre_y_.span(particles_), centre_z_.span(particles_)};
    }
    ConstKernelShapes kernel_shapes() const {
        return {shape_sxx_.span(particles_), shape_sxy_.span(particles_), shape_syy_.span(particles_),
                shape_gx_.span(particles_),  shape_gy_.span(particles_),  shape_c_.span(particles_),
                shape_amp_.span(particles_)};
    }

    // Sweep scratch for `workers` blocks at once (otherwise grown on demand, one per concurrently running
    // block, the first frames); call at setup with the thread count for an allocation-free first frame.
    void reserve_scratch(std::size_t workers);

    // ---- per-frame jobs; `p` must be the same positions for every job of a frame ----
    void begin_frame(ConstPositions p);  // throws on too many particles, non-finite ones, grid limits
    std::uint32_t chunks() const { return chunks_; }
    // Items of the shape job: chunks() with anisotropic kernels, else 0.
    static constexpr std::uint32_t kShapeChunk = 1024;  // particles per shape item (each costs ~2 us)
    std::uint32_t shape_chunks() const {
        return settings_.anisotropy > 0
                   ? static_cast<std::uint32_t>((particles_ + kShapeChunk - 1) / kShapeChunk)
                   : 0;
    }
    void shape(ConstPositions p, std::uint32_t chunk);
    void block_count(ConstPositions p, std::uint32_t chunk);
    void block_prefix();
    void block_scatter(ConstPositions p, std::uint32_t chunk);
    std::uint32_t blocks() const { return active_count_; }  // non-empty blocks, the items below
    std::uint32_t block_id(std::uint32_t item) const { return active_[item]; }
    // Item i extracts the block with the i-th most listed particles (ties in block order), so that at
    // the end of the job the threads are not waiting for one large block; output goes to the block's
    // own slot, so the schedule does not change the mesh.
    void extract_block(std::uint32_t item);
    void weld_offsets(SurfaceMesh& out);
    void weld_block(std::uint32_t item, SurfaceMesh& out);
    void normals_block(std::uint32_t item);
    void borders();
    void stage(std::uint32_t item, SurfaceMesh& out);

    void extract_serial(ConstPositions p, SurfaceMesh& out);

    // ---- one frame split into pieces (runtime/lib/mesh_decomposition.h) ----
    // Fixes the grid and the field to the whole frame's, for frames that are subsets of its particles (a
    // slab of blocks and its ghost margin): their blocks lie where the whole frame's do, and a block whose
    // particles are all present is the same bytes as in the whole frame. Call before the first frame;
    // throws with anisotropic kernels (their shapes need every neighbour of a particle).
    void fix_frame(ConstPositions whole);
    // A vertex whose owner block lies beyond a piece's particles (only at the piece's rim) is this index
    // in the welded mesh instead of an error; the caller keeps only blocks away from the rim.
    static constexpr std::uint32_t kMissingVertex = 0xffffffffu;
    // The triangles active block `item` (0 .. blocks() - 1, block order) holds in the welded mesh.
    std::uint64_t block_triangle_offset(std::uint32_t item) const { return slots_[item].triangle_offset; }
    std::uint32_t block_triangle_count(std::uint32_t item) const { return slots_[item].triangles_n; }

    const SlicesStats& stats() const { return stats_; }

  private:
    struct OwnerVertex {
        std::uint32_t item;    // the owner's active-block index
        std::uint32_t vertex;  // its block-local (owned) vertex
    };
    struct BlockSlot {
        AlignedArray<float> positions;  // 4 per vertex (x, y, z, 0)
        AlignedArray<std::uint32_t> triangles;
        AlignedArray<KeyedVertex> border;          // owned vertices other blocks may refer to, sorted by key
        AlignedArray<KeyedVertex> foreign;         // vertices other blocks own, in creation order (borders)
        AlignedArray<OwnerVertex> foreign_owner;   // where each foreign vertex lives
        AlignedArray<std::uint32_t> foreign_mesh;  // its mesh index
        AlignedArray<float> acc;                   // normal accumulators, 4 per vertex
        // Block-local vertices: owned 0 .. owned - 1, foreign capacity - foreign_n .. capacity - 1.
        std::uint32_t capacity = 0, triangles_n = 0, owned = 0, border_n = 0, foreign_n = 0;
        std::uint32_t particles = 0, cache_entries = 0;  // what the block's sweep scratch had to hold
        std::uint64_t vertex_offset = 0, triangle_offset = 0;
        BlockSweepStats sweep;
    };
    struct Scratch;
    Scratch& acquire_scratch();
    void release_scratch(Scratch& s);
    // Grows every sweep scratch to what the largest block of this frame needed, so that which worker
    // meets which block never decides in which frame a buffer grows (serial; allocates only when a frame
    // needs more than any before).
    void grow_scratch(std::uint32_t particles, std::uint32_t cache_entries);
    std::uint32_t owner_of(std::uint64_t key) const;
    // The particles' bounds; throws std::invalid_argument naming the first non-finite coordinate.
    void frame_bounds(ConstPositions p, float lo[3], float hi[3]) const;
    // The block grid around lo..hi with the field's reach and padding.
    void place_grid(const float lo[3], const float hi[3]);
    void apply_field(const SliceFieldValues& field);
    // Throws std::length_error when an axis needs more than settings_.max_grid_cubes cubes.
    void check_grid_cubes(double cells) const;
    // Measures the data's spacing (jobs/particle_spacing.h) and sets the spacing field from it (serial).
    void resolve_field(ConstPositions p, const float lo[3], const float hi[3]);
    // What the blocks are built from: the smoothed centres with anisotropic kernels, else `p`.
    ConstPositions centres(ConstPositions p) const;
    AnisotropyParams anisotropy_params() const;

    SlicesSettings settings_;
    std::size_t max_particles_;
    SliceFieldValues field_;
    bool field_resolved_ = false;
    std::vector<std::uint32_t> spacing_heads_, spacing_order_;  // particle_spacing's workspace
    std::vector<float> spacing_values_;
    // Anisotropic kernels: the neighbour hash (built in begin_frame), centres and shapes per particle
    // (sized for max_particles at construction).
    std::vector<std::uint32_t> hash_heads_, hash_order_;
    std::vector<float> hash_x_, hash_y_, hash_z_;
    CellHash hash_;
    AlignedArray<float> centre_x_, centre_y_, centre_z_;
    AlignedArray<float> shape_sxx_, shape_sxy_, shape_syy_, shape_gx_, shape_gy_, shape_c_, shape_amp_;
    float rc_ = 0, iso_ = 0, voxel_ = 0;
    SliceGrid grid_;
    bool fixed_frame_ = false;  // fix_frame: the grid's bounds are the whole frame's
    float fixed_lo_[3] = {0, 0, 0}, fixed_hi_[3] = {0, 0, 0};

    std::size_t particles_ = 0;
    std::uint32_t chunks_ = 0;
    std::uint32_t entries_ = 0;
    std::uint32_t active_count_ = 0;
    SlicesStats stats_;

    AlignedArray<std::uint32_t> chunk_counts_, chunk_cursors_, block_offsets_, block_entries_;
    AlignedArray<float> entry_x_, entry_y_, entry_z_;
    AlignedArray<std::uint32_t> active_;
    AlignedArray<std::uint32_t> schedule_;  // extract_block's items, most listed particles first
    // Faces between non-empty blocks, scanned once for both (SharedFace): slot 3 a + axis is the min face
    // of active block a along that axis; its state is reset every frame.
    AlignedArray<std::uint32_t> face_state_;
    AlignedArray<std::uint64_t> face_bits_;
    AlignedArray<std::int32_t> block_to_active_;
    std::vector<BlockSlot> slots_;

    std::mutex scratch_mutex_;
    std::vector<std::unique_ptr<Scratch>> scratch_;
    std::vector<Scratch*> free_scratch_;
};

}  // namespace rivulet
