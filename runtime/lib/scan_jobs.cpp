#include "runtime/lib/scan_jobs.h"

namespace rivulet {

ScanJobIds add_scan_jobs(FrameGraph& g, ScanConverter& scan, std::function<ConstPositions()> positions,
                         std::function<ScanOutput&()> output,
                         std::initializer_list<FrameGraph::JobId> after) {
    ScanJobIds id{};
    auto& s = scan;
    auto pos = std::move(positions);
    auto out = std::move(output);
    const auto begin = g.serial(
        "scan.begin", [&s, pos] { s.begin_frame(pos()); }, after);
    id.bin_count = g.parallel(
        "scan.bin_count", [&s] { return std::size_t(s.chunks()); },
        [&s, pos](std::size_t c) { s.bin_count(pos(), static_cast<std::uint32_t>(c)); }, {begin});
    id.bin_prefix = g.serial("scan.bin_prefix", [&s] { s.bin_prefix(); }, {id.bin_count});
    id.bin_scatter = g.parallel(
        "scan.bin_scatter", [&s] { return std::size_t(s.chunks()); },
        [&s, pos](std::size_t c) { s.bin_scatter(pos(), static_cast<std::uint32_t>(c)); }, {id.bin_prefix});
    id.bin_neighbours = g.parallel(
        "scan.neighbours", [&s] { return std::size_t(s.bins_count()); },
        [&s](std::size_t b) { s.bin_neighbours(static_cast<std::uint32_t>(b)); }, {id.bin_scatter});
    id.grouping = g.serial("scan.group", [&s] { s.group(); }, {id.bin_neighbours});
    const auto spread = g.parallel(
        "scan.spread", [&s] { return std::size_t(s.bin_chunks()); },
        [&s](std::size_t c) { s.spread(static_cast<std::uint32_t>(c)); }, {id.grouping});
    const auto offsets = g.serial("scan.list_offsets", [&s] { s.list_offsets(); }, {spread});
    id.group_lists = g.parallel(
        "scan.lists", [&s] { return std::size_t(s.bin_chunks()); },
        [&s](std::size_t c) { s.lists(static_cast<std::uint32_t>(c)); }, {offsets});
    id.deform = g.parallel(
        "scan.deform", [&s] { return std::size_t(s.pieces()); },
        [&s, pos, out](std::size_t i) { s.deform(pos(), static_cast<std::uint32_t>(i), out()); },
        {id.group_lists});
    id.normals = g.parallel(
        "scan.normals", [&s] { return std::size_t(s.pieces()); },
        [&s, out](std::size_t i) { s.normals(static_cast<std::uint32_t>(i), out()); }, {id.deform});
    id.isolated = g.serial("scan.isolated", [&s, pos, out] { s.isolated(pos(), out()); }, {id.group_lists});
    id.stage = g.serial("scan.stage", [&s, out] { s.stage(out()); }, {id.normals, id.isolated});
    return id;
}

OrientedScanJobIds add_oriented_scan_jobs(FrameGraph& g, OrientedScan& scan,
                                          std::function<ConstPositions()> positions,
                                          std::function<ScanOutput&()> output,
                                          std::initializer_list<FrameGraph::JobId> after,
                                          std::function<void()> split) {
    auto& s = scan;
    auto pos = std::move(positions);
    auto out = std::move(output);
    OrientedScanJobIds id{};
    const auto link = g.serial(
        "oriented.link", [&s, pos] { s.link(pos()); }, after);
    const auto skeleton = g.parallel(
        "oriented.skeleton", [&s] { return std::size_t(s.components()); },
        [&s, pos](std::size_t c) { s.skeleton(pos(), static_cast<std::uint32_t>(c)); }, {link});
    const auto cylinders = g.serial("oriented.cylinders", [&s] { s.cylinders(); }, {skeleton});
    id.rings = g.parallel(
        "oriented.rings", [&s] { return std::size_t(s.branches()); },
        [&s, pos, out](std::size_t b) { s.rings(pos(), static_cast<std::uint32_t>(b), out()); }, {cylinders});
    const bool splits = static_cast<bool>(split);
    id.split = splits ? g.serial("hybrid.split", std::move(split), {id.rings}) : ~FrameGraph::JobId{0};
    const FrameGraph::JobId ready = splits ? id.split : id.rings;
    const auto normals = g.parallel(
        "oriented.normals", [&s] { return std::size_t(s.branches()); },
        [&s, out](std::size_t b) { s.normals(static_cast<std::uint32_t>(b), out()); }, {ready});
    const auto isolated =
        g.serial("oriented.isolated", [&s, pos, out] { s.isolated(pos(), out()); }, {ready});
    id.stage = g.serial("oriented.stage", [&s, out] { s.stage(out()); }, {normals, isolated});
    return id;
}

}  // namespace rivulet
