#pragma once
// The marching-slices jobs of a frame graph (Janisz §3.2), shared by `mesh` (alone) and, later, `run`.
// See SlicesExtractor for what each job does. Job names carry the `slices.` prefix:
//   slices.begin -> slices.shape* (anisotropic kernels only) -> slices.count* -> slices.prefix ->
//   slices.scatter* -> slices.blocks*, then both slices.offsets -> slices.weld* and slices.normals* (a
//   block's own sums need no offsets), then slices.borders -> slices.stage* (* = parallel items)
#include <functional>
#include <initializer_list>

#include "runtime/lib/frame_graph.h"
#include "systems/slices/slices_extractor.h"

namespace rivulet {

struct SlicesJobIds {
    FrameGraph::JobId begin, shape, count, prefix, scatter, blocks, offsets, weld, normals, borders, stage;
};

// `positions` and `output` are asked when each job runs, so they may change between frames (slots).
SlicesJobIds add_slices_jobs(FrameGraph& graph, SlicesExtractor& slices,
                             std::function<ConstPositions()> positions, std::function<SurfaceMesh&()> output,
                             std::initializer_list<FrameGraph::JobId> after = {});

}  // namespace rivulet
