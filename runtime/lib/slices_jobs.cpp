#include "runtime/lib/slices_jobs.h"

namespace rivulet {

SlicesJobIds add_slices_jobs(FrameGraph& g, SlicesExtractor& slices,
                             std::function<ConstPositions()> positions, std::function<SurfaceMesh&()> output,
                             std::initializer_list<FrameGraph::JobId> after) {
    SlicesJobIds id{};
    auto& s = slices;
    auto pos = std::move(positions);
    auto out = std::move(output);
    auto item = [](std::size_t i) { return static_cast<std::uint32_t>(i); };
    id.begin = g.serial(
        "slices.begin", [&s, pos] { s.begin_frame(pos()); }, after);
    id.shape = g.parallel(
        "slices.shape", [&s] { return std::size_t(s.shape_chunks()); },
        [&s, pos, item](std::size_t c) { s.shape(pos(), item(c)); }, {id.begin});
    id.count = g.parallel(
        "slices.count", [&s] { return std::size_t(s.chunks()); },
        [&s, pos, item](std::size_t c) { s.block_count(pos(), item(c)); }, {id.shape});
    id.prefix = g.serial("slices.prefix", [&s] { s.block_prefix(); }, {id.count});
    id.scatter = g.parallel(
        "slices.scatter", [&s] { return std::size_t(s.chunks()); },
        [&s, pos, item](std::size_t c) { s.block_scatter(pos(), item(c)); }, {id.prefix});
    id.blocks = g.parallel(
        "slices.blocks", [&s] { return std::size_t(s.blocks()); },
        [&s, item](std::size_t b) { s.extract_block(item(b)); }, {id.scatter});
    id.offsets = g.serial("slices.offsets", [&s, out] { s.weld_offsets(out()); }, {id.blocks});
    id.weld = g.parallel(
        "slices.weld", [&s] { return std::size_t(s.blocks()); },
        [&s, out, item](std::size_t b) { s.weld_block(item(b), out()); }, {id.offsets});
    id.normals = g.parallel(
        "slices.normals", [&s] { return std::size_t(s.blocks()); },
        [&s, item](std::size_t b) { s.normals_block(item(b)); }, {id.blocks});
    id.borders = g.serial("slices.borders", [&s] { s.borders(); }, {id.normals, id.weld});
    id.stage = g.parallel(
        "slices.stage", [&s] { return std::size_t(s.blocks()); },
        [&s, out, item](std::size_t b) { s.stage(item(b), out()); }, {id.borders});
    return id;
}

}  // namespace rivulet
