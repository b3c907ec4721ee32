#include "runtime/lib/hybrid_extractor.h"

#include "runtime/lib/scan_jobs.h"
#include "runtime/lib/slices_jobs.h"

namespace rivulet {

HybridExtractor::HybridExtractor(const ScanSettings& scan, const SlicesSettings& slices,
                                 std::size_t max_particles)
    : scan_(scan, max_particles),
      slices_(slices, max_particles),
      radius_(scan.radius),
      max_particles_(max_particles) {
    scan_.set_thick_node_beads(kThickNodeBeads);
    to_slices_.reserve(max_particles);
    x_.reserve(max_particles), y_.reserve(max_particles), z_.reserve(max_particles);
}

ConstPositions HybridExtractor::slices_particles() const {
    return {x_.span(subset_), y_.span(subset_), z_.span(subset_)};
}

void HybridExtractor::split(ConstPositions p, ScanOutput& cylinders) {
    scan_.split_streams(p, kStreamRadii * radius_, kStreamAspect, cylinders, to_slices_.span(max_particles_));
    subset_ = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (!to_slices_[i]) continue;
        x_[subset_] = p.x[i], y_[subset_] = p.y[i], z_[subset_] = p.z[i];
        ++subset_;
    }
}

FrameGraph::JobId HybridExtractor::add_jobs(FrameGraph& graph, std::function<ConstPositions()> positions,
                                            std::function<ScanOutput&()> cylinders,
                                            std::function<SurfaceMesh&()> mesh,
                                            std::initializer_list<FrameGraph::JobId> after) {
    const OrientedScanJobIds scan =
        add_oriented_scan_jobs(graph, scan_, positions, cylinders, after,
                               [this, positions, cylinders] { split(positions(), cylinders()); });
    const SlicesJobIds slices =
        add_slices_jobs(graph, slices_, [this] { return slices_particles(); }, std::move(mesh), {scan.split});
    return graph.serial("hybrid.join", [] {}, {scan.stage, slices.stage});
}

}  // namespace rivulet
