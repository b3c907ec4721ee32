#pragma once
// Sphere scan conversion with cylinders oriented along each stream (`axis: path`; the seed's future work):
// the same cylinder pool, output and renderer as ScanConverter, with the V-axis bins and groups replaced
// by the stream's own path (jobs/stream_skeleton.h, jobs/oriented_rings.h). Jobs of a frame, in order
// (* = independent items, run in parallel):
//
//   link               beads: the particles of each cell one grouping distance wide, at their centroid
//                      (a stream holds tens of particles per link, the path needs a few points per link);
//                      their links by a sweep in cell order (jobs/grid_links.h); components
//   -> skeleton(c)*    per component of two or more particles: geodesic levels, nodes, branches of beads
//   -> cylinders       a pool cylinder per branch, in component order (beyond the pool: spheres)
//   -> rings(b)*       per branch: path, ring frames, radii, positions
//   -> normals(b)*     per branch (jobs/cylinder_normals.h)
//   -> isolated, stage
#include <cstdint>

#include "jobs/cylinder_layout.h"
#include "jobs/grid_links.h"
#include "jobs/oriented_rings.h"
#include "jobs/particle_spans.h"
#include "jobs/stream_skeleton.h"
#include "jobs/vec3.h"
#include "systems/particles/aligned_array.h"
#include "systems/scan/scan_output.h"
#include "systems/scan/scan_settings.h"

namespace rivulet {

class OrientedScan {
  public:
    // Throws std::invalid_argument when settings.validate() fails.
    OrientedScan(const ScanSettings& settings, std::size_t max_particles);

    const ScanSettings& settings() const { return settings_; }
    const CylinderLayout& layout() const { return layout_; }
    void prepare_output(ScanOutput& out) const;

    // ---- per-frame jobs; `p` must be the same positions for every job of a frame ----
    void link(ConstPositions p);
    std::uint32_t components() const { return components_; }
    void skeleton(ConstPositions p, std::uint32_t component);
    void cylinders();
    std::uint32_t branches() const { return drawn_; }
    void rings(ConstPositions p, std::uint32_t branch, ScanOutput& out);
    void normals(std::uint32_t branch, ScanOutput& out);
    void isolated(ConstPositions p, ScanOutput& out);
    void stage(ScanOutput& out);

    void extract_serial(ConstPositions p, ScanOutput& out);

    // The hybrid method's split (runtime/lib/hybrid_extractor.h), after rings, given the frame's output:
    // in each branch the longest run of rings whose mean radius is at most `max_radius` stays a cylinder
    // (drawn over that run only) when the run is at least `min_aspect` times as long as its widest ring;
    // to_slices[i] = 1 (one flag per particle) for the particles of the other branches and those nearest
    // a ring outside the run, and for a stream's particles within one bead link of those (so the blob's
    // surface swallows the end of the stream's tube). normals and stage then draw the runs only.
    void split_streams(ConstPositions p, float max_radius, float min_aspect, ScanOutput& out,
                       std::span<std::uint8_t> to_slices);
    // Level nodes of more beads than this start a branch of their own (SkeletonParams::thick_node), so a
    // stream and the blob it runs into are two branches; 0 (the default) follows streams into blobs.
    void set_thick_node_beads(std::uint32_t beads) { thick_node_beads_ = beads; }
    bool is_stream(std::uint32_t branch) const { return stream_[branch] != 0; }

    // A drawn branch's particles (for tests and the hybrid method's ownership rule), once rings ran.
    std::span<const std::uint32_t> branch_particles(std::uint32_t branch) const;
    const OrientedTube& tube(std::uint32_t branch) const { return tube_[branch]; }

  private:
    // A fork's child branch needs this many beads (with its subtree) to stand apart.
    static constexpr std::uint32_t kMinBranchBeads = 3;
    // Bead cells one grouping distance wide, beads linked within 1.5 of it (a bead's centroid sits anywhere
    // in its cell, so two linked particles' beads can be farther apart than they are). On the fountain
    // these find the same streams as half-width cells at a third of the cost.
    static constexpr float kBeadCell = 1.0f;
    static constexpr float kBeadLink = 1.5f;
    float bead_link() const;
    ScanSettings settings_;
    CylinderLayout layout_;
    std::uint32_t thick_node_beads_ = 0;
    std::size_t max_particles_;
    std::size_t particles_ = 0;
    AlignedArray<float> cos_t_, sin_t_;

    // Cells of two beads linked are at most this many apart (kBeadLink / kBeadCell, rounded up).
    static constexpr std::uint32_t kLinkReach = 2;
    static_assert(kLinkReach >= kBeadLink / kBeadCell);
    AlignedArray<std::uint32_t> order_tmp_, counts_;
    AlignedArray<std::uint64_t> cell_key_, key_tmp_, bead_key_;
    AlignedArray<std::uint32_t> by_cell_, bead_first_;  // particles by bead; bead b's: [first[b], first[b+1])
    AlignedArray<std::uint32_t> pair_a_, pair_b_;       // the beads' links, once each (jobs/grid_links.h)
    AlignedArray<float> pair_length_;
    AlignedArray<float> bead_x_, bead_y_, bead_z_;
    std::uint32_t beads_ = 0;
    ConstPositions bead_positions() const;
    AlignedArray<std::uint32_t> link_first_, link_to_;  // the beads' links (LinkGraph)
    AlignedArray<float> link_length_;
    LinkGraph link_graph() const;
    // Beads grouped by component; a drawn branch's particles, by level, at particle_at_[its first bead].
    AlignedArray<std::uint32_t> root_, members_, member_pos_, component_first_, component_end_, particle_at_;
    AlignedArray<std::uint32_t> branch_particles_, branch_levels_;
    std::uint32_t components_ = 0;

    AlignedArray<float> dist_;
    AlignedArray<std::uint32_t> heap_, heap_pos_, level_, node_, sort_order_, link_root_;
    AlignedArray<std::uint32_t> node_level_, node_size_, node_weight_, node_parents_, node_children_,
        node_first_edge_, node_branch_, node_mode_, edge_from_, edge_to_;
    SkeletonScratch scratch(std::uint32_t component);
    AlignedArray<BranchRange> branch_ranges_;
    const BranchRange& drawn_range(std::uint32_t drawn) const;  // component c's at [component_first_[c], ...)
    AlignedArray<std::uint32_t> branch_counts_;

    // Drawn branches (pool cylinders), in component order.
    std::uint32_t drawn_ = 0, undrawn_ = 0;
    AlignedArray<std::uint32_t> drawn_component_, drawn_branch_, bead_drawn_;
    AlignedArray<OrientedTube> tube_;
    AlignedArray<std::uint8_t> stream_, bead_blob_;
    AlignedArray<std::uint32_t> draw_first_, draw_last_;     // the rings drawn of each branch
    AlignedArray<float> ring_x_, ring_y_, ring_z_, ring_r_;  // split_streams' scratch, one per ring
    static constexpr float kSeamEndScale = 0.5f, kSeamInnerScale = 0.8f;
    void taper_seams(ConstPositions p, std::uint32_t branch, std::span<const std::uint8_t> to_slices,
                     ScanOutput& out);
    Vec3f ring_centre(const float* vertices, std::uint32_t ring) const;
    void scale_ring(float* vertices, std::uint32_t ring, float scale) const;
    AlignedArray<float> path_x_, path_y_, path_z_, arc_, member_x_, member_y_, member_z_, circle_x_,
        circle_z_, circle_rho_;
    AlignedArray<std::uint32_t> level_start_, cut_first_, ring_first_, ring_cursor_;
    AlignedArray<std::uint8_t> cut_count_;
    AlignedArray<float> frames_, planes_;
    AlignedArray<std::uint8_t> grouped_;
};

}  // namespace rivulet
