#pragma once
// Sphere scan conversion as a system (Hoetzlein & Höllerer 2009 §2): owns the persistent buffers (bins, group
// lists, circle scratch, angle tables) sized once for a particle capacity, and exposes the per-frame jobs the
// frame graph schedules, in this order (* = independent items, run in parallel):
//
//   bin_count(chunk)* -> bin_prefix -> bin_scatter(chunk)*       hash sort into V bins (jobs/bin_sort.h)
//   -> bin_neighbours(bin)* -> group -> spread(bin chunk)*       grouping (jobs/bin_neighbours.h,
//   -> list_offsets -> lists(bin chunk)*                         grouping.h, group_lists.h)
//   -> deform(piece)* -> normals(piece)*                         per cylinder piece (jobs/deform_cylinder.h,
//                                                                cylinder_normals.h)
//   -> isolated (beside deform)                                  sphere instances (jobs/isolated_particles.h)
//   -> stage                                                     draw list, counters
//
// extract_serial() runs the same jobs in order on the calling thread.
#include <cstdint>

#include "jobs/bin_sort.h"
#include "jobs/cylinder_layout.h"
#include "jobs/deform_cylinder.h"
#include "jobs/grouping.h"
#include "jobs/particle_chunks.h"
#include "jobs/particle_spans.h"
#include "systems/particles/aligned_array.h"
#include "systems/scan/scan_output.h"
#include "systems/scan/scan_settings.h"

namespace rivulet {

class ScanConverter {
  public:
    static constexpr ParticleChunks kChunks{};  // the bin sort's chunks
    // Rings per piece: deformation and normals run per piece of a cylinder, not per cylinder, so one
    // long stream still spreads over every worker and pieces of unequal groups balance.
    static constexpr std::uint32_t kRingsPerPiece = 16;
    // Bins per chunk of the grouping's parallel passes over the bin table (spread, lists).
    static constexpr std::uint32_t kBinsPerChunk = 8;

    // The buffers one converter reserves (bins, groups, the cylinder pool's vertices) at most.
    static constexpr std::uint64_t kMaxScanBufferBytes = std::uint64_t{4} << 30;

    // Throws std::invalid_argument when settings.validate() fails or the buffers would exceed
    // kMaxScanBufferBytes.
    ScanConverter(const ScanSettings& settings, std::size_t max_particles);

    const ScanSettings& settings() const { return settings_; }
    const CylinderLayout& layout() const { return layout_; }
    const BinGrid& grid() const { return grid_; }
    std::size_t max_particles() const { return max_particles_; }
    // Sizes a slot's output buffers for this converter (allocates: call at setup).
    void prepare_output(ScanOutput& out) const;

    // ---- per-frame jobs; `p` must be the same positions for every job of a frame ----
    void begin_frame(ConstPositions p);  // checks the count against capacity, sets chunk count
    std::uint32_t chunks() const { return chunks_; }
    void bin_count(ConstPositions p, std::uint32_t chunk);
    void bin_prefix();
    void bin_scatter(ConstPositions p, std::uint32_t chunk);
    std::uint32_t bins_count() const { return grid_.bins; }
    void bin_neighbours(std::uint32_t bin);  // neighbour links and the bin's grouping events
    void group();                            // the paper's rules over the events (serial)
    std::uint32_t groups() const { return grouping_.groups; }
    std::uint32_t bin_chunks() const { return (grid_.bins + kBinsPerChunk - 1) / kBinsPerChunk; }
    void spread(std::uint32_t bin_chunk);  // every entry's group, and the chunk's counts per group
    void list_offsets();                   // group list offsets, isolated count, cylinder pieces
    void lists(std::uint32_t bin_chunk);   // the chunk's entries into the group lists
    // Pieces of this frame's cylinders (set by group()): piece i is rings [first, last] of one group.
    std::uint32_t pieces() const { return pieces_; }
    void deform(ConstPositions p, std::uint32_t piece, ScanOutput& out);
    void normals(std::uint32_t piece, ScanOutput& out);
    void isolated(ConstPositions p, ScanOutput& out);
    void stage(ScanOutput& out);

    void extract_serial(ConstPositions p, ScanOutput& out);

    BinTableView bins() const;
    std::span<const std::int32_t> entry_group() const { return entry_group_.span(entries_); }
    std::span<const std::uint8_t> grouped() const { return grouped_.span(particles_); }
    GroupingResult grouping_result() const { return grouping_; }
    std::uint32_t group_vmin(std::uint32_t g) const { return vmin_[g]; }
    std::uint32_t group_vmax(std::uint32_t g) const { return vmax_[g]; }

  private:
    ScanSettings settings_;
    CylinderLayout layout_;
    BinGrid grid_;
    std::size_t max_particles_;
    std::size_t entry_capacity_;
    std::uint32_t max_chunks_;

    std::size_t particles_ = 0;
    std::uint32_t chunks_ = 0;
    std::uint32_t entries_ = 0;
    GroupingResult grouping_;

    AlignedArray<float> cos_t_, sin_t_;
    AlignedArray<std::uint32_t> chunk_counts_, chunk_cursors_, bin_offsets_, bin_entries_;
    AlignedArray<float> entry_x_, entry_y_, entry_z_;
    AlignedArray<std::int32_t> entry_group_;
    AlignedArray<std::uint8_t> grouped_;
    AlignedArray<std::uint32_t> particle_first_bin_, particle_end_bin_;
    ParticleBins particle_bins(std::size_t begin, std::size_t n);
    AlignedArray<std::uint32_t> blocked_bin_, link_, root_, tree_size_, events_, event_count_;
    // Storage of one set of per-bin hash tables (jobs/bin_neighbours.h); the neighbour jobs need two.
    struct HashTables {
        AlignedArray<std::uint32_t> start, items, bucket;
        AlignedArray<float> x, y, z;
        void reserve(std::size_t entries, std::size_t bins);
        BinHashes view(std::size_t entries);
    };
    HashTables own_hashes_, above_hashes_;
    AlignedArray<std::uint32_t> list_offsets_, list_bin_, list_particle_, vmin_, vmax_;
    AlignedArray<std::uint32_t> chunk_group_counts_, chunk_group_cursors_, chunk_isolated_;
    std::span<std::uint32_t> chunk_span(AlignedArray<std::uint32_t>& a, std::uint32_t bin_chunk);
    LinkForest forest();
    std::uint32_t group_row() const;
    AlignedArray<float> circle_cx_, circle_cz_, circle_rho_;
    std::uint32_t pieces_ = 0;
    AlignedArray<std::uint32_t> piece_group_, piece_first_;
    void split_into_pieces();
};

}  // namespace rivulet
