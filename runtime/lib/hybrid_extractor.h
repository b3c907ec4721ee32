#pragma once
// The hybrid method: streams as cylinders along their path, everything else as marching slices, in one
// frame graph (the stream-or-blob split that Hoetzlein & Höllerer 2009 suggest for scan conversion's
// limits). OrientedScan finds the branches and their rings; a branch stays a cylinder when it is a stream
// (its widest ring's mean radius at most kStreamRadii sphere radii, its path at least kStreamAspect times
// that long); the other branches' particles go to a SlicesExtractor. The seam rule: a stream's particles
// within one bead link of a blob's are meshed by both, so the blob's closed surface swallows the end of
// the stream's closed tube and no gap opens where a stream enters a blob. Isolated particles stay spheres.
//
//   oriented.link -> oriented.skeleton* -> oriented.cylinders -> oriented.rings* -> hybrid.split
//   -> oriented.normals*, oriented.isolated -> oriented.stage
//   -> slices.* (on the split's particles)                         -> hybrid.join
#include <cstdint>
#include <functional>
#include <initializer_list>

#include "runtime/lib/frame_graph.h"
#include "systems/particles/aligned_array.h"
#include "systems/scan/oriented_scan.h"
#include "systems/scan/scan_output.h"
#include "systems/slices/slices_extractor.h"
#include "systems/slices/surface_mesh.h"

namespace rivulet {

class HybridExtractor {
  public:
    static constexpr float kStreamRadii = 3.0f;
    static constexpr float kStreamAspect = 4.0f;
    // A level (1.5 grouping distances of path) of a stream a few radii wide holds a handful of beads
    // (cells one grouping distance wide); more, and the skeleton cuts the branch there.
    static constexpr std::uint32_t kThickNodeBeads = 6;

    // `scan.radius` and `slices.radius` are the particle radius (the same); throws std::invalid_argument
    // on bad settings.
    HybridExtractor(const ScanSettings& scan, const SlicesSettings& slices, std::size_t max_particles);

    const OrientedScan& scan() const { return scan_; }
    const SlicesExtractor& slices() const { return slices_; }
    void prepare_output(ScanOutput& out) const { scan_.prepare_output(out); }
    void reserve_scratch(std::size_t threads) { slices_.reserve_scratch(threads); }
    // The particles meshed by marching slices this frame (after hybrid.split).
    ConstPositions slices_particles() const;

    // Adds the jobs; returns hybrid.join, which ends the frame's surface.
    FrameGraph::JobId add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                               std::function<ScanOutput&()> cylinders, std::function<SurfaceMesh&()> mesh,
                               std::initializer_list<FrameGraph::JobId> after = {});

  private:
    void split(ConstPositions p, ScanOutput& cylinders);
    OrientedScan scan_;
    SlicesExtractor slices_;
    float radius_;
    std::size_t max_particles_, subset_ = 0;
    AlignedArray<std::uint8_t> to_slices_;
    AlignedArray<float> x_, y_, z_;
};

}  // namespace rivulet
