#include "systems/volume/volume_builder.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "jobs/chunk_prefix.h"
#include "jobs/mesh_hash.h"

namespace rivulet {
namespace {

// Per-chunk rows of the bin sort's tables start on their own cache lines: chunks counted or scattered on
// different cores would otherwise share the lines between their rows, and every count and cursor
// increment would bounce them between the cores.
std::size_t chunk_row(std::size_t groups) {
    constexpr std::size_t kWordsPerLine = 64 / sizeof(std::uint32_t);
    return (groups + kWordsPerLine - 1) / kWordsPerLine * kWordsPerLine;
}

}  // namespace

DensityVolumeView DensityVolume::view() const {
    DensityVolumeView v;
    v.grid = grid;
    v.iso = iso;
    v.brick_slot = brick_slot.span(grid.bricks());
    v.slot_brick = slot_brick.span(stored);
    v.slot_min = slot_min.span(stored);
    v.slot_max = slot_max.span(stored);
    v.atlas = atlas.span(stored ? atlas_samples(atlas_layers(stored)) : 0);
    return v;
}

std::uint64_t DensityVolume::hash() const {
    Hasher h;
    const float header[6] = {grid.ox, grid.oy, grid.oz, grid.voxel, grid.h, iso};
    const std::uint32_t dims[4] = {grid.bx, grid.by, grid.bz, stored};
    h.add(header, sizeof header);
    h.add(dims, sizeof dims);
    h.add(brick_slot.data(), grid.bricks() * sizeof(std::int32_t));
    for (std::uint32_t s = 0; s < stored; ++s)
        for (std::uint32_t k = 0; k < kBrickEdge; ++k)
            for (std::uint32_t j = 0; j < kBrickEdge; ++j)
                h.add(atlas.data() + atlas_offset(s, 0, j, k), kBrickEdge * sizeof(float));
    return h.digest();
}

VolumeBuilder::VolumeBuilder(const VolumeSettings& settings, std::size_t max_particles)
    : settings_(settings), max_particles_(max_particles) {
    if (const std::string problem = settings.validate(); !problem.empty())
        throw std::invalid_argument(problem);
    iso_ = settings.iso_value();
    chunking_ = ParticleChunks::at_most(max_particles, kMaxChunks);
    const std::size_t per_axis = settings.max_dim / kBrickCells;
    max_grid_bricks_ = per_axis * per_axis * per_axis;
    const std::size_t groups_x = (per_axis + kGroupBricksX - 1) / kGroupBricksX,
                      groups_y = (per_axis + kGroupBricksY - 1) / kGroupBricksY,
                      groups_z = (per_axis + kGroupBricksZ - 1) / kGroupBricksZ;
    max_groups_ = groups_x * groups_y * groups_z;
    const std::size_t n = std::max<std::size_t>(max_particles, 1);
    // Entries: about 2.1 per particle at the default kernel and voxel (1.5 where the voxel grew and the
    // kernel spans about two); grown by offsets() when a frame needs more.
    entries_.reserve(3 * n);
    const std::size_t rows = chunk_row(max_groups_) * kMaxChunks;
    counts_.reserve(rows), cursors_.reserve(rows), masks_.reserve(rows);
    bin_start_.reserve(max_groups_ + 1);
    splat_group_.reserve(max_groups_);
}

void VolumeBuilder::prepare(DensityVolume& out) const {
    out.brick_slot.reserve(max_grid_bricks_);
    const std::size_t slots = std::min<std::size_t>(settings_.max_bricks, max_grid_bricks_);
    out.slot_brick.reserve(slots), out.slot_min.reserve(slots), out.slot_max.reserve(slots);
    out.iso = iso_;
}

std::size_t VolumeBuilder::chunks(std::size_t n) const {
    return std::max<std::size_t>(chunking_.count(n), 1);
}

ConstPositions VolumeBuilder::chunk(ConstPositions p, std::size_t c) const {
    const std::size_t n = std::min(p.size(), max_particles_);
    const ParticleRange r = chunking_.range(c, n);
    return p.subspan(r.begin, r.count);
}

void VolumeBuilder::bounds_chunk(ConstPositions p, std::size_t c) {
    const ConstPositions part = chunk(p, c);
    chunk_bounds_[c] = part.size() ? particle_bounds(part) : ParticleBounds{};
}

void VolumeBuilder::plan(DensityVolume& out, std::size_t n) {
    n = std::min(n, max_particles_);
    frame_chunks_ = chunks(n);
    ParticleBounds b = chunk_bounds_[0];
    for (std::size_t c = 1; c < frame_chunks_; ++c) b = merge_bounds(b, chunk_bounds_[c]);
    out.grid = plan_density_grid(b, settings_.grid_params());
    out.iso = iso_;
    out.stored = 0;
    splat_groups_ = 0;
    frame_groups_ = density_groups(out.grid).count();
    frame_row_ = chunk_row(frame_groups_);
    std::memset(counts_.data(), 0, frame_row_ * frame_chunks_ * sizeof(std::uint32_t));
    std::memset(masks_.data(), 0, frame_row_ * frame_chunks_ * sizeof(GroupBrickMask));
}

void VolumeBuilder::count_chunk(const DensityVolume& out, ConstPositions p, std::size_t c) {
    const ConstPositions part = chunk(p, c);
    const std::size_t row = frame_row_;
    density_bin_count_chunk(out.grid, part, counts_.span(c * row + frame_groups_).subspan(c * row),
                            masks_.span(c * row + frame_groups_).subspan(c * row));
}

void VolumeBuilder::offsets(const DensityVolume&, std::size_t) {
    const auto groups = static_cast<std::uint32_t>(frame_groups_);
    const auto n = static_cast<std::uint32_t>(frame_chunks_);
    const std::uint32_t entries =
        chunk_major_prefix(groups, n, frame_row_, counts_.span(std::size_t(n) * frame_row_),
                           cursors_.span(std::size_t(n) * frame_row_), bin_start_.span(groups + 1));
    // The chunks' brick masks into chunk 0's.
    GroupBrickMask* merged = masks_.data();
    for (std::size_t c = 1; c < frame_chunks_; ++c) {
        const GroupBrickMask* m = masks_.data() + c * frame_row_;
        for (std::uint32_t g = 0; g < groups; ++g) merged[g] |= m[g];
    }
    if (entries_.capacity() < entries) entries_.reserve(entries + entries / 4);
}

void VolumeBuilder::scatter_chunk(const DensityVolume& out, ConstPositions p, std::size_t c) {
    const ConstPositions part = chunk(p, c);
    const auto first =
        static_cast<std::uint32_t>(chunking_.range(c, std::min(p.size(), max_particles_)).begin);
    density_bin_scatter_chunk(out.grid, part, first,
                              cursors_.span(c * frame_row_ + frame_groups_).subspan(c * frame_row_),
                              entries_.span(entries_.capacity()));
}

void VolumeBuilder::allocate(DensityVolume& out) {
    const std::uint32_t bricks = out.grid.bricks();
    const std::uint32_t stored = density_allocate_bricks(
        out.grid, masks_.span(frame_groups_), out.brick_slot.span(bricks),
        out.slot_brick.span(out.slot_brick.capacity()), splat_group_.span(frame_groups_), splat_groups_);
    if (stored > settings_.max_bricks)
        throw std::runtime_error(fmt::format(
            "density volume: {} bricks reached, more than the limit of {}: use a larger --voxel or a smaller "
            "--max-dim",
            stored, settings_.max_bricks));
    out.stored = stored;
    const std::size_t need = atlas_samples(atlas_layers(stored));
    if (out.atlas.capacity() < need) out.atlas.reserve(need + need / 4);
}

std::size_t VolumeBuilder::splat_items(const DensityVolume&) const {
    return std::max<std::size_t>((splat_groups_ + kSplatGroups - 1) / kSplatGroups, 1);
}

void VolumeBuilder::splat_item(DensityVolume& out, ConstPositions p, const ParticleVolumes& volumes,
                               std::size_t item) const {
    if (volumes.given() && volumes.density.size() < p.size())
        throw std::logic_error("VolumeBuilder::splat_item: fewer densities than particles");
    const std::span<const std::uint32_t> entries = entries_.span(bin_start_[frame_groups_]);
    const std::span<float> atlas = out.atlas.span(out.atlas.capacity());
    const std::size_t first = item * kSplatGroups,
                      last = std::min<std::size_t>(first + kSplatGroups, splat_groups_);
    const std::uint32_t bricks = out.grid.bricks();
    for (std::size_t i = first; i < last; ++i)
        density_splat_group(out.grid, splat_group_[i], p, volumes, entries,
                            bin_start_.span(frame_groups_ + 1), out.brick_slot.span(bricks), atlas,
                            out.slot_min.span(out.stored), out.slot_max.span(out.stored));
}

}  // namespace rivulet
