#include "systems/scan/scan_converter.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "jobs/chunk_prefix.h"
#include "jobs/cylinder_normals.h"
#include "jobs/group_lists.h"
#include "jobs/isolated_particles.h"

namespace rivulet {

ScanConverter::ScanConverter(const ScanSettings& settings, std::size_t max_particles)
    : settings_(settings), max_particles_(max_particles) {
    if (const std::string err = settings.validate(); !err.empty()) throw std::invalid_argument(err);
    if (max_particles == 0 || max_particles > (std::size_t(1) << 31))
        throw std::invalid_argument("particle capacity must be in [1, 2^31], got " +
                                    std::to_string(max_particles));
    layout_ = {settings.u, settings.v};
    grid_.top = settings.v_top;
    grid_.spacing = (settings.v_top - settings.v_bottom) / static_cast<float>(settings.v - 1);
    grid_.bins = settings.v;
    grid_.radius = settings.radius;

    entry_capacity_ = max_particles * std::min<std::size_t>(grid_.max_bins_per_particle(), settings.v);
    // Grouping links keep entry indices in 31 bits (jobs/bin_neighbours.h).
    if (entry_capacity_ >= (std::size_t(1) << 31))
        throw std::invalid_argument(
            "particles x cross-sections per particle reach 2^31 bin entries: lower --v or --radius");
    max_chunks_ = static_cast<std::uint32_t>(kChunks.count(max_particles));
    // Everything below and prepare_output reserve, estimated first: a pool far beyond memory (say
    // --max-groups 100000) is refused with its cause instead of failing as std::bad_alloc.
    const std::size_t max_row = (settings.max_groups + kGroupRowAlign - 1) / kGroupRowAlign * kGroupRowAlign;
    const std::size_t max_pieces =
        std::size_t(settings.max_groups) * ((settings.v + kRingsPerPiece - 1) / kRingsPerPiece);
    const double bytes =
        4.0 * (26.0 * double(entry_capacity_) + 6.0 * double(max_particles) +
               2.0 * double(max_chunks_) * grid_.bins + 2.0 * bin_chunks() * double(max_row) +
               2.0 * double(max_pieces) + 6.0 * double(settings.max_groups) * layout_.verts_per_cylinder());
    if (bytes > double(kMaxScanBufferBytes))
        throw std::invalid_argument(fmt::format(
            "scan conversion buffers for --max-groups {}, --u {}, --v {} and {} particles would take {:.1f} "
            "GiB (limit {} GiB): lower them",
            settings.max_groups, settings.u, settings.v, max_particles, bytes / double(1 << 30),
            kMaxScanBufferBytes >> 30));

    cos_t_.reserve(settings.u), sin_t_.reserve(settings.u);
    fill_angle_table(cos_t_.span(settings.u), sin_t_.span(settings.u));
    chunk_counts_.reserve(std::size_t(max_chunks_) * grid_.bins);
    chunk_cursors_.reserve(std::size_t(max_chunks_) * grid_.bins);
    bin_offsets_.reserve(grid_.bins + 1);
    bin_entries_.reserve(entry_capacity_);
    entry_x_.reserve(entry_capacity_), entry_y_.reserve(entry_capacity_), entry_z_.reserve(entry_capacity_);
    entry_group_.reserve(entry_capacity_);
    grouped_.reserve(max_particles);
    particle_first_bin_.reserve(max_particles), particle_end_bin_.reserve(max_particles);
    blocked_bin_.reserve(settings.max_groups);
    own_hashes_.reserve(entry_capacity_, grid_.bins);
    above_hashes_.reserve(entry_capacity_, grid_.bins);
    link_.reserve(entry_capacity_), root_.reserve(entry_capacity_), tree_size_.reserve(entry_capacity_),
        events_.reserve(entry_capacity_), event_count_.reserve(grid_.bins);
    list_offsets_.reserve(settings.max_groups + 1);
    list_bin_.reserve(entry_capacity_), list_particle_.reserve(entry_capacity_);
    vmin_.reserve(settings.max_groups), vmax_.reserve(settings.max_groups);
    chunk_group_counts_.reserve(std::size_t(bin_chunks()) * max_row);
    chunk_group_cursors_.reserve(std::size_t(bin_chunks()) * max_row);
    chunk_isolated_.reserve(bin_chunks());
    circle_cx_.reserve(entry_capacity_), circle_cz_.reserve(entry_capacity_),
        circle_rho_.reserve(entry_capacity_);
    piece_group_.reserve(max_pieces), piece_first_.reserve(max_pieces);
}

void ScanConverter::prepare_output(ScanOutput& out) const {
    out.vertices.reserve(std::size_t(settings_.max_groups) * layout_.verts_per_cylinder() * 6);
    out.draws.reserve(settings_.max_groups);
    out.sphere_centers.reserve(max_particles_ * 3);
}

void ScanConverter::begin_frame(ConstPositions p) {
    if (p.size() > max_particles_)
        throw std::length_error("scan conversion capacity " + std::to_string(max_particles_) +
                                " exceeded by " + std::to_string(p.size()) + " particles");
    particles_ = p.size();
    chunks_ = static_cast<std::uint32_t>(kChunks.count(particles_));
    grouping_ = {};
    pieces_ = 0;
}

void ScanConverter::bin_count(ConstPositions p, std::uint32_t chunk) {
    const ParticleRange r = kChunks.range(chunk, particles_);
    bin_count_chunk(
        grid_, p.y.subspan(r.begin, r.count),
        chunk_counts_.span(chunk_counts_.capacity()).subspan(std::size_t(chunk) * grid_.bins, grid_.bins),
        particle_bins(r.begin, r.count));
}

ParticleBins ScanConverter::particle_bins(std::size_t begin, std::size_t n) {
    return {particle_first_bin_.span(max_particles_).subspan(begin, n),
            particle_end_bin_.span(max_particles_).subspan(begin, n)};
}

void ScanConverter::bin_prefix() {
    entries_ = rivulet::bin_prefix(grid_.bins, chunks_, chunk_counts_.span(std::size_t(chunks_) * grid_.bins),
                                   chunk_cursors_.span(std::size_t(chunks_) * grid_.bins),
                                   bin_offsets_.span(grid_.bins + 1));
}

void ScanConverter::bin_scatter(ConstPositions p, std::uint32_t chunk) {
    const ParticleRange r = kChunks.range(chunk, particles_);
    bin_scatter_chunk(
        p.subspan(r.begin, r.count), static_cast<std::uint32_t>(r.begin), particle_bins(r.begin, r.count),
        chunk_cursors_.span(chunk_cursors_.capacity()).subspan(std::size_t(chunk) * grid_.bins, grid_.bins),
        {bin_entries_.span(entry_capacity_), entry_x_.span(entry_capacity_), entry_y_.span(entry_capacity_),
         entry_z_.span(entry_capacity_)});
}

BinTableView ScanConverter::bins() const {
    return {bin_offsets_.span(grid_.bins + 1), bin_entries_.span(entries_), entry_x_.span(entries_),
            entry_y_.span(entries_), entry_z_.span(entries_)};
}

void ScanConverter::HashTables::reserve(std::size_t entries, std::size_t bins) {
    start.reserve(bin_hash_start_capacity(entries, bins));
    items.reserve(entries), bucket.reserve(entries);
    x.reserve(entries), y.reserve(entries), z.reserve(entries);
}

BinHashes ScanConverter::HashTables::view(std::size_t entries) {
    return {
        start.span(start.capacity()), items.span(entries), x.span(entries), y.span(entries), z.span(entries),
        bucket.span(entries)};
}

void ScanConverter::bin_neighbours(std::uint32_t bin) {
    const BinTableView table = bins();
    find_bin_neighbours(table, bin, settings_.grouping_distance(), own_hashes_.view(entries_),
                        above_hashes_.view(entries_), link_.span(entries_));
    event_count_[bin] =
        collect_group_events(table, bin, link_.span(entries_), forest(), events_.span(entries_));
}

LinkForest ScanConverter::forest() {
    return {root_.span(entries_), tree_size_.span(entries_)};
}

void ScanConverter::group() {
    grouping_ = assign_groups(bins(), link_.span(entries_), forest(),
                              {events_.span(entries_), event_count_.span(grid_.bins)}, settings_.max_groups,
                              entry_group_.span(entries_),
                              {vmin_.span(settings_.max_groups), vmax_.span(settings_.max_groups),
                               blocked_bin_.span(settings_.max_groups)});
}

// Each chunk's row of per-group counters starts on its own cache line: a chunk's job bumps a counter per
// entry, and with one long stream every chunk bumps group 0's.
std::uint32_t ScanConverter::group_row() const {
    return (grouping_.groups + kGroupRowAlign - 1) / kGroupRowAlign * kGroupRowAlign;
}

std::span<std::uint32_t> ScanConverter::chunk_span(AlignedArray<std::uint32_t>& a, std::uint32_t bin_chunk) {
    return a.span(std::size_t(bin_chunks()) * group_row())
        .subspan(std::size_t(bin_chunk) * group_row(), grouping_.groups);
}

void ScanConverter::spread(std::uint32_t bin_chunk) {
    const BinTableView table = bins();
    const std::uint32_t first = bin_chunk * kBinsPerChunk, end = std::min(first + kBinsPerChunk, grid_.bins);
    for (std::uint32_t b = first; b < end; ++b)
        spread_groups(table, b, forest(), entry_group_.span(entries_));
    chunk_isolated_[bin_chunk] = count_group_entries(table, first, end, entry_group_.span(entries_),
                                                     chunk_span(chunk_group_counts_, bin_chunk));
}

void ScanConverter::list_offsets() {
    const std::uint32_t groups = grouping_.groups, chunks = bin_chunks();
    const std::uint32_t row = group_row();
    chunk_major_prefix(groups, chunks, row, chunk_group_counts_.span(std::size_t(chunks) * row),
                       chunk_group_cursors_.span(std::size_t(chunks) * row), list_offsets_.span(groups + 1));
    grouping_.isolated_entries = 0;
    for (std::uint32_t c = 0; c < chunks; ++c) grouping_.isolated_entries += chunk_isolated_[c];
    split_into_pieces();
}

void ScanConverter::lists(std::uint32_t bin_chunk) {
    const std::uint32_t first = bin_chunk * kBinsPerChunk, end = std::min(first + kBinsPerChunk, grid_.bins);
    scatter_group_entries(bins(), first, end, entry_group_.span(entries_),
                          chunk_span(chunk_group_cursors_, bin_chunk),
                          {list_bin_.span(entries_), list_particle_.span(entries_)});
}

void ScanConverter::split_into_pieces() {
    pieces_ = 0;
    for (std::uint32_t g = 0; g < grouping_.groups; ++g) {
        for (std::uint32_t first = vmin_[g]; first <= vmax_[g]; first += kRingsPerPiece) {
            piece_group_[pieces_] = g;
            piece_first_[pieces_] = first;
            ++pieces_;
        }
    }
}

void ScanConverter::deform(ConstPositions p, std::uint32_t piece, ScanOutput& out) {
    const std::uint32_t g = piece_group_[piece], first = piece_first_[piece];
    const std::uint32_t last = std::min(first + kRingsPerPiece - 1, vmax_[g]);
    // The group's list is in ring order: the piece's entries are one run of it.
    const std::uint32_t* list = list_bin_.data();
    const std::uint32_t* from = std::lower_bound(list + list_offsets_[g], list + list_offsets_[g + 1], first);
    const std::uint32_t* to = std::upper_bound(from, list + list_offsets_[g + 1], last);
    const auto begin = static_cast<std::size_t>(from - list), n = static_cast<std::size_t>(to - from);
    const DeformParams params{
        grid_, layout_, settings_.section, {cos_t_.span(settings_.u), sin_t_.span(settings_.u)}};
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    deform_cylinder(p, list_bin_.span(entries_).subspan(begin, n),
                    list_particle_.span(entries_).subspan(begin, n), vmin_[g], vmax_[g], params,
                    circle_cx_.span(entries_).subspan(begin, n), circle_cz_.span(entries_).subspan(begin, n),
                    circle_rho_.span(entries_).subspan(begin, n),
                    out.vertices.span(out.vertices.capacity()).subspan(g * vpc, vpc));
}

void ScanConverter::normals(std::uint32_t piece, ScanOutput& out) {
    const std::uint32_t g = piece_group_[piece], first = piece_first_[piece];
    const std::uint32_t last = std::min(first + kRingsPerPiece - 1, vmax_[g]);
    const std::size_t vpc = std::size_t(layout_.verts_per_cylinder()) * 6;
    cylinder_normals(layout_, vmin_[g], vmax_[g], first, last,
                     out.vertices.span(out.vertices.capacity()).subspan(g * vpc, vpc));
}

void ScanConverter::isolated(ConstPositions p, ScanOutput& out) {
    mark_grouped_particles(list_particle_.span(list_offsets_[grouping_.groups]), grouped_.span(particles_));
    out.sphere_count =
        collect_isolated(p, grouped_.span(particles_), out.sphere_centers.span(particles_ * 3));
}

void ScanConverter::stage(ScanOutput& out) {
    std::uint64_t triangles = 0;
    for (std::uint32_t g = 0; g < grouping_.groups; ++g) {
        out.draws[g] = {g, vmin_[g], vmax_[g]};
        triangles += 2ull * layout_.u * (vmax_[g] - vmin_[g]) + 2ull * layout_.u;
    }
    out.draw_count = grouping_.groups;
    out.bin_entries = entries_;
    out.pool_exhausted = grouping_.pool_exhausted;
    out.triangles = triangles;
}

void ScanConverter::extract_serial(ConstPositions p, ScanOutput& out) {
    begin_frame(p);
    for (std::uint32_t c = 0; c < chunks_; ++c) bin_count(p, c);
    bin_prefix();
    for (std::uint32_t c = 0; c < chunks_; ++c) bin_scatter(p, c);
    for (std::uint32_t b = 0; b < grid_.bins; ++b) bin_neighbours(b);
    group();
    for (std::uint32_t c = 0; c < bin_chunks(); ++c) spread(c);
    list_offsets();
    for (std::uint32_t c = 0; c < bin_chunks(); ++c) lists(c);
    for (std::uint32_t i = 0; i < pieces(); ++i) deform(p, i, out);
    for (std::uint32_t i = 0; i < pieces(); ++i) normals(i, out);
    isolated(p, out);
    stage(out);
}

}  // namespace rivulet
