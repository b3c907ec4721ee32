#include "runtime/lib/volume_jobs.h"

namespace rivulet {

FrameGraph::JobId add_volume_jobs(FrameGraph& graph, VolumeBuilder& builder,
                                  std::function<ConstPositions()> positions,
                                  std::function<DensityVolume&()> out,
                                  std::initializer_list<FrameGraph::JobId> after,
                                  std::function<ParticleVolumes()> volumes) {
    VolumeBuilder* b = &builder;
    if (!volumes) volumes = [] { return ParticleVolumes{}; };
    const auto chunks = [b, positions] { return b->chunks(positions().size()); };
    const FrameGraph::JobId bounds = graph.parallel(
        "volume.bounds", chunks, [b, positions](std::size_t c) { b->bounds_chunk(positions(), c); }, after);
    const FrameGraph::JobId grid =
        graph.serial("volume.grid", [b, positions, out] { b->plan(out(), positions().size()); }, {bounds});
    const FrameGraph::JobId count =
        graph.parallel("volume.bin_count", chunks,
                       [b, positions, out](std::size_t c) { b->count_chunk(out(), positions(), c); }, {grid});
    const FrameGraph::JobId offsets = graph.serial(
        "volume.bin_offsets", [b, positions, out] { b->offsets(out(), positions().size()); }, {count});
    const FrameGraph::JobId scatter = graph.parallel(
        "volume.bin_scatter", chunks,
        [b, positions, out](std::size_t c) { b->scatter_chunk(out(), positions(), c); }, {offsets});
    const FrameGraph::JobId allocate =
        graph.serial("volume.allocate", [b, out] { b->allocate(out()); }, {scatter});
    return graph.parallel(
        "volume.splat", [b, out] { return b->splat_items(out()); },
        [b, positions, out, volumes](std::size_t item) {
            b->splat_item(out(), positions(), volumes(), item);
        },
        {allocate});
}

}  // namespace rivulet
