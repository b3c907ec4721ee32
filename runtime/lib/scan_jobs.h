#pragma once
// The sphere scan conversion jobs of a frame graph (the pipeline of Hoetzlein & Höllerer 2009), shared by
// `run` (after the simulation jobs) and `mesh` (alone). See ScanConverter for what each job does.
#include <functional>
#include <initializer_list>

#include "runtime/lib/frame_graph.h"
#include "systems/scan/oriented_scan.h"
#include "systems/scan/scan_converter.h"

namespace rivulet {

struct ScanJobIds {
    FrameGraph::JobId bin_count, bin_prefix, bin_scatter, bin_neighbours, grouping, group_lists, deform,
        normals, isolated, stage;
};

// `positions` and `output` are asked when each job runs, so they may change between frames (slots).
ScanJobIds add_scan_jobs(FrameGraph& graph, ScanConverter& scan, std::function<ConstPositions()> positions,
                         std::function<ScanOutput&()> output,
                         std::initializer_list<FrameGraph::JobId> after = {});

struct OrientedScanJobIds {
    FrameGraph::JobId rings, split, stage;  // split: ~0u without one
};

// The jobs of OrientedScan. With `split` (the hybrid method), a serial job "hybrid.split" runs it after
// the rings and before the normals, spheres and stage.
OrientedScanJobIds add_oriented_scan_jobs(FrameGraph& graph, OrientedScan& scan,
                                          std::function<ConstPositions()> positions,
                                          std::function<ScanOutput&()> output,
                                          std::initializer_list<FrameGraph::JobId> after = {},
                                          std::function<void()> split = {});

}  // namespace rivulet
