#pragma once
// The density volume's jobs in a frame graph (systems/volume/volume_builder.h holds their state):
//   volume.bounds*  -> volume.grid -> volume.bin_count* -> volume.bin_offsets -> volume.bin_scatter*
//   -> volume.allocate -> volume.splat*
// (* = parallel). `positions`, `out` and `volumes` (the particles' own volumes, where a simulation gives
// them; none: V from the radius) are asked when each job runs.
#include <functional>

#include "runtime/lib/frame_graph.h"
#include "systems/volume/volume_builder.h"

namespace rivulet {

FrameGraph::JobId add_volume_jobs(FrameGraph& graph, VolumeBuilder& builder,
                                  std::function<ConstPositions()> positions,
                                  std::function<DensityVolume&()> out,
                                  std::initializer_list<FrameGraph::JobId> after = {},
                                  std::function<ParticleVolumes()> volumes = {});

}  // namespace rivulet
