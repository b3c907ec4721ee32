#include "systems/slices/slices_extractor.h"

#include <fmt/format.h>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "jobs/angle_normals.h"
#include "jobs/bin_sort.h"
#include "jobs/block_bins.h"
#include "jobs/particle_spacing.h"
#include "jobs/weld_indices.h"

namespace rivulet {
namespace {

// Grows `a` to hold `n` (rare; allocates), without keeping its contents.
template <class T>
void ensure(AlignedArray<T>& a, std::size_t n) {
    if (n > a.capacity()) a.reserve(std::max(n, a.capacity() + a.capacity() / 2));
}

}  // namespace

struct SlicesExtractor::Scratch {
    AlignedArray<std::uint32_t> order, sort_counts, column_offsets;
    AlignedArray<std::int32_t> mids;
    AlignedArray<ColumnEntry> entries;
    AlignedArray<AnisoEntry> aniso_entries;
    AlignedArray<std::uint16_t> rows;
    AlignedArray<float> slices;
    AlignedArray<std::uint64_t> face_bits, slice_rows, slab_rows, edge_rows, work_rows;
    AlignedArray<std::int32_t> slab_range, walk_lo, walk_hi;
    AlignedArray<std::uint32_t> edges;

    explicit Scratch(const SliceGrid& g) {
        const SliceScratchSizes z(g.n);
        sort_counts.reserve(lookup_sort_slots(g));
        column_offsets.reserve(lookup_offset_slots(g));
        slices.reserve(z.slices), face_bits.reserve(z.face_bits);
        slice_rows.reserve(z.slice_rows), slab_rows.reserve(z.slab_rows), edge_rows.reserve(z.edge_rows);
        work_rows.reserve(z.work_rows), slab_range.reserve(z.slab_range);
        walk_lo.reserve(z.columns), walk_hi.reserve(z.columns);
        edges.reserve(z.edges);
    }
    SliceScratch view(const SliceGrid& g) {
        const SliceScratchSizes z(g.n);
        return {slices.span(z.slices),         face_bits.span(z.face_bits), slice_rows.span(z.slice_rows),
                slab_rows.span(z.slab_rows),   edge_rows.span(z.edge_rows), work_rows.span(z.work_rows),
                slab_range.span(z.slab_range), edges.span(z.edges),         walk_lo.span(z.columns),
                walk_hi.span(z.columns)};
    }
};

SlicesExtractor::SlicesExtractor(const SlicesSettings& settings, std::size_t max_particles)
    : settings_(settings), max_particles_(max_particles) {
    if (const std::string err = settings.validate(); !err.empty()) throw std::invalid_argument(err);
    if (max_particles == 0 || max_particles > (std::size_t(1) << 28))
        throw std::invalid_argument(
            fmt::format("particle capacity must be in [1, 2^28], got {}", max_particles));
    voxel_ = settings.voxel_size();
    grid_.set_voxel(voxel_);
    grid_.set_block_cubes(settings.block_cubes);
    // Until the spacing field is measured (first non-empty frame), the grid claims the widest reach any
    // spacing can give, so sweep scratch reserved before then is large enough.
    if (settings.anisotropy > 0) {
        hash_heads_.resize(cell_hash_table_size(max_particles) + 1), hash_order_.resize(max_particles);
        hash_x_.resize(max_particles), hash_y_.resize(max_particles), hash_z_.resize(max_particles);
        for (auto* a : {&centre_x_, &centre_y_, &centre_z_, &shape_sxx_, &shape_sxy_, &shape_syy_, &shape_gx_,
                        &shape_gy_, &shape_c_, &shape_amp_})
            a->reserve(max_particles);
    }
    field_resolved_ = settings.field == SliceField::kClassic || settings.spacing > 0;
    apply_field(field_resolved_ ? settings.field_values(0) : SliceFieldValues{settings.max_rc(), 0, 0});
}

void SlicesExtractor::apply_field(const SliceFieldValues& field) {
    field_ = field;
    rc_ = field.rc, iso_ = field.iso;
    grid_.rc = rc_;
    // A particle in cell c reaches the corners within R, in exact arithmetic [c - ceil(R) + 1, c +
    // ceil(R)] for R = R_c / voxel (times the longest axis of an anisotropic kernel); the grid claims
    // [c - reach, c + reach + 1] with reach = ceil(R), one corner more on each side, a whole voxel of
    // margin against rounding of cells and distances (a wider margin makes every column lookup scan more
    // entries, and blocks list more particles).
    grid_.reach = static_cast<std::int32_t>(std::ceil(rc_ * settings_.reach_factor() / voxel_));
}

AnisotropyParams SlicesExtractor::anisotropy_params() const {
    // The classic field is calibrated for data two radii apart.
    const float spacing = field_.spacing > 0 ? field_.spacing : 2.0f * settings_.radius;
    return {kAnisotropyNeighbourhood * spacing, settings_.anisotropy, settings_.anisotropy_smoothing,
            kAnisotropyMinNeighbours};
}

ConstPositions SlicesExtractor::centres(ConstPositions p) const {
    return settings_.anisotropy > 0 ? kernel_centres() : p;
}

void SlicesExtractor::shape(ConstPositions p, std::uint32_t chunk) {
    const std::size_t begin = std::size_t(chunk) * kShapeChunk,
                      end = std::min(particles_, begin + kShapeChunk);
    anisotropic_kernels(p, hash_, begin, end, anisotropy_params(),
                        {centre_x_.span(particles_), centre_y_.span(particles_), centre_z_.span(particles_),
                         shape_sxx_.span(particles_), shape_sxy_.span(particles_),
                         shape_syy_.span(particles_), shape_gx_.span(particles_), shape_gy_.span(particles_),
                         shape_c_.span(particles_), shape_amp_.span(particles_)});
}

void SlicesExtractor::resolve_field(ConstPositions p, const float lo[3], const float hi[3]) {
    const float cell = static_cast<float>(kMaxFieldSpacing) * settings_.radius;
    // The spacing's hash cells are at least a quarter of `cell`, which is at least half a voxel: this
    // bounds their indices as particle_spacing requires.
    for (int a = 0; a < 3; ++a) check_grid_cubes((double(hi[a]) - double(lo[a])) / voxel_);
    // Kept between frames: a run whose frames stay under the sample measures every frame.
    spacing_heads_.resize(std::max(spacing_heads_.size(), cell_hash_table_size(p.size()) + 1));
    spacing_order_.resize(std::max(spacing_order_.size(), p.size()));
    spacing_values_.resize(kSpacingSamples);
    const float spacing =
        particle_spacing(p, lo, cell, kSpacingSamples, {spacing_heads_, spacing_order_, spacing_values_});
    apply_field(settings_.field_values(spacing));
    // A frame with fewer particles than the sample (a fountain's first streams) is measured for itself
    // only: the spacing is fixed by the first frame that fills the sample.
    field_resolved_ = p.size() >= kSpacingSamples;
}

void SlicesExtractor::check_grid_cubes(double cells) const {
    if (cells > settings_.max_grid_cubes)
        throw std::length_error(
            fmt::format("marching slices grid needs {} cubes along an axis (limit {}): raise --voxel", cells,
                        settings_.max_grid_cubes));
}

SlicesExtractor::~SlicesExtractor() = default;

SlicesExtractor::Scratch& SlicesExtractor::acquire_scratch() {
    std::lock_guard<std::mutex> lock(scratch_mutex_);
    if (free_scratch_.empty()) {  // one per concurrently running block: grows to the thread count once
        scratch_.push_back(std::make_unique<Scratch>(grid_));
        free_scratch_.reserve(scratch_.size());
        return *scratch_.back();
    }
    Scratch* s = free_scratch_.back();
    free_scratch_.pop_back();
    return *s;
}

void SlicesExtractor::reserve_scratch(std::size_t workers) {
    std::lock_guard<std::mutex> lock(scratch_mutex_);
    while (scratch_.size() < workers) {
        scratch_.push_back(std::make_unique<Scratch>(grid_));
        free_scratch_.reserve(scratch_.size());
        free_scratch_.push_back(scratch_.back().get());
    }
}

void SlicesExtractor::grow_scratch(std::uint32_t particles, std::uint32_t cache_entries) {
    std::lock_guard<std::mutex> lock(scratch_mutex_);
    for (const auto& s : scratch_) {
        ensure(s->order, particles), ensure(s->mids, particles);
        ensure(s->rows, std::size_t(particles) * lookup_row_slots(grid_));
        // The reach sets these; it grows when a frame's field is measured again (forget_field) with a
        // wider R_c than the frame the scratch was made for.
        ensure(s->sort_counts, lookup_sort_slots(grid_)),
            ensure(s->column_offsets, lookup_offset_slots(grid_));
        if (settings_.anisotropy > 0)
            ensure(s->aniso_entries, cache_entries);
        else
            ensure(s->entries, cache_entries);
    }
}

void SlicesExtractor::release_scratch(Scratch& s) {
    std::lock_guard<std::mutex> lock(scratch_mutex_);
    free_scratch_.push_back(&s);
}

void SlicesExtractor::frame_bounds(ConstPositions p, float lo[3], float hi[3]) const {
    const std::size_t count = p.size();
    lo[0] = hi[0] = p.x[0], lo[1] = hi[1] = p.y[0], lo[2] = hi[2] = p.z[0];
    const std::span<const float> axes[3] = {p.x, p.y, p.z};
    // Bounds without a branch per coordinate: v - v is NaN exactly when v is NaN or infinite. Only when
    // some coordinate is, the slow loop finds the first (axis by axis) for the message.
    bool finite = true;
    for (int a = 0; a < 3; ++a) {
        float l[4] = {lo[a], lo[a], lo[a], lo[a]}, h[4] = {hi[a], hi[a], hi[a], hi[a]};
        bool ok[4] = {true, true, true, true};
        const float* v = axes[a].data();
        std::size_t i = 0;
        for (; i + 4 <= count; i += 4)
            for (int q = 0; q < 4; ++q) {
                const float x = v[i + std::size_t(q)];
                ok[q] &= (x - x) == 0.0f;
                l[q] = x < l[q] ? x : l[q], h[q] = x > h[q] ? x : h[q];
            }
        for (; i < count; ++i) {
            ok[0] &= (v[i] - v[i]) == 0.0f;
            l[0] = v[i] < l[0] ? v[i] : l[0], h[0] = v[i] > h[0] ? v[i] : h[0];
        }
        for (int q = 0; q < 4; ++q)
            finite &= ok[q], lo[a] = std::min(lo[a], l[q]), hi[a] = std::max(hi[a], h[q]);
    }
    if (!finite)
        for (int a = 0; a < 3; ++a)
            for (std::size_t i = 0; i < count; ++i)
                if (!std::isfinite(axes[a][i]))
                    throw std::invalid_argument(fmt::format("particle {} has a non-finite coordinate", i));
}

void SlicesExtractor::place_grid(const float lo[3], const float hi[3]) {
    float origin[3];
    std::uint32_t nb[3];
    for (int a = 0; a < 3; ++a) {
        const double first = std::floor(double(lo[a]) / voxel_), last = std::floor(double(hi[a]) / voxel_);
        const double cells = last - first + 2.0 * grid_.reach + 6.0;
        check_grid_cubes(cells);
        origin[a] = static_cast<float>((first - grid_.reach - 2.0) * voxel_);
        nb[a] = static_cast<std::uint32_t>(std::ceil(cells / grid_.n));
    }
    grid_.ox = origin[0], grid_.oy = origin[1], grid_.oz = origin[2];
    grid_.bx = nb[0], grid_.by = nb[1], grid_.bz = nb[2];
}

void SlicesExtractor::fix_frame(ConstPositions whole) {
    if (settings_.anisotropy > 0)
        throw std::invalid_argument(
            "a frame split into pieces takes spherical kernels only (no --anisotropic)");
    if (whole.size() == 0) throw std::invalid_argument("no particles to mesh");
    float lo[3], hi[3];
    frame_bounds(whole, lo, hi);
    if (!field_resolved_) resolve_field(whole, lo, hi);
    field_resolved_ = true;
    place_grid(lo, hi);
    for (int a = 0; a < 3; ++a) fixed_lo_[a] = lo[a], fixed_hi_[a] = hi[a];
    fixed_frame_ = true;
}

void SlicesExtractor::begin_frame(ConstPositions p) {
    if (p.size() > max_particles_)
        throw std::length_error(
            fmt::format("marching slices capacity {} exceeded by {} particles", max_particles_, p.size()));
    particles_ = p.size();
    chunks_ = static_cast<std::uint32_t>(kChunks.count(particles_));
    stats_ = {};
    active_count_ = 0;
    entries_ = 0;
    if (particles_ == 0) {
        grid_.bx = grid_.by = grid_.bz = 0;
        return;
    }
    float lo[3], hi[3];
    frame_bounds(p, lo, hi);
    if (fixed_frame_) {
        for (int a = 0; a < 3; ++a) {
            if (lo[a] < fixed_lo_[a] || hi[a] > fixed_hi_[a])
                throw std::logic_error("marching slices: particles outside the fixed frame's bounds");
            lo[a] = fixed_lo_[a], hi[a] = fixed_hi_[a];
        }
    }
    if (!field_resolved_) resolve_field(p, lo, hi);
    // The smoothed centres are weighted means of positions: inside these bounds too.
    if (settings_.anisotropy > 0) {
        hash_ = build_cell_hash(p, lo, anisotropy_params().radius, hash_heads_, hash_order_);
        sort_cell_hash_positions(hash_, p, hash_x_, hash_y_, hash_z_);
    }
    place_grid(lo, hi);
    const std::uint32_t nb[3] = {grid_.bx, grid_.by, grid_.bz};
    const std::uint64_t blocks = std::uint64_t(nb[0]) * nb[1] * nb[2];
    if (blocks * chunks_ > (std::uint64_t(1) << 28))
        throw std::length_error(fmt::format(
            "marching slices grid of {} blocks is too sparse for {} particles: raise --voxel or --block",
            blocks, particles_));
    ensure(chunk_counts_, std::size_t(blocks) * chunks_);
    ensure(chunk_cursors_, std::size_t(blocks) * chunks_);
    ensure(block_offsets_, std::size_t(blocks) + 1);
    ensure(active_, std::size_t(blocks));
    ensure(schedule_, std::size_t(blocks));
    ensure(block_to_active_, std::size_t(blocks));
    stats_.blocks = static_cast<std::uint32_t>(blocks);
}

void SlicesExtractor::block_count(ConstPositions p, std::uint32_t chunk) {
    const ParticleRange r = kChunks.range(chunk, particles_);
    const std::size_t blocks = grid_.blocks();
    block_count_chunk(grid_, centres(p).subspan(r.begin, r.count),
                      chunk_counts_.span(std::size_t(chunks_) * blocks).subspan(chunk * blocks, blocks));
}

void SlicesExtractor::block_prefix() {
    const std::uint32_t blocks = grid_.blocks();
    if (particles_ == 0) return;
    const std::uint64_t listed = [&] {
        std::uint64_t t = 0;
        for (std::size_t i = 0; i < std::size_t(blocks) * chunks_; ++i) t += chunk_counts_[i];
        return t;
    }();
    if (listed > (std::uint64_t(1) << 31))
        throw std::length_error("marching slices: more than 2^31 particle-in-block listings");
    entries_ =
        bin_prefix(blocks, chunks_, chunk_counts_.span(std::size_t(blocks) * chunks_),
                   chunk_cursors_.span(std::size_t(blocks) * chunks_), block_offsets_.span(blocks + 1));
    ensure(block_entries_, entries_);
    ensure(entry_x_, entries_), ensure(entry_y_, entries_), ensure(entry_z_, entries_);
    std::uint32_t active = 0;
    for (std::uint32_t b = 0; b < blocks; ++b) {
        if (block_offsets_[b + 1] == block_offsets_[b]) {
            block_to_active_[b] = -1;
            continue;
        }
        block_to_active_[b] = static_cast<std::int32_t>(active);
        active_[active++] = b;
    }
    if (active > settings_.max_blocks)
        throw std::length_error(fmt::format(
            "marching slices: {} non-empty blocks exceed the limit of {} (raise --block or max_blocks)",
            active, settings_.max_blocks));
    if (slots_.size() < active) slots_.resize(active);  // rare: the most blocks seen so far
    ensure(face_state_, std::size_t(active) * 3);
    ensure(face_bits_, std::size_t(active) * 3 * SliceScratchSizes(grid_.n).face_bits);
    std::fill(face_state_.data(), face_state_.data() + std::size_t(active) * 3, kFaceFree);
    std::uint32_t* order = schedule_.data();
    for (std::uint32_t a = 0; a < active; ++a) order[a] = a;
    auto particles_in = [&](std::uint32_t a) {
        return block_offsets_[active_[a] + 1] - block_offsets_[active_[a]];
    };
    std::sort(order, order + active, [&](std::uint32_t x, std::uint32_t y) {
        const std::uint32_t px = particles_in(x), py = particles_in(y);
        return px != py ? px > py : x < y;
    });
    active_count_ = active;
    stats_.active_blocks = active;
    stats_.block_entries = entries_;
}

void SlicesExtractor::block_scatter(ConstPositions p, std::uint32_t chunk) {
    const ParticleRange r = kChunks.range(chunk, particles_);
    const std::size_t blocks = grid_.blocks();
    block_scatter_chunk(grid_, centres(p).subspan(r.begin, r.count), static_cast<std::uint32_t>(r.begin),
                        chunk_cursors_.span(std::size_t(chunks_) * blocks).subspan(chunk * blocks, blocks),
                        {block_entries_.span(entries_), entry_x_.span(entries_), entry_y_.span(entries_),
                         entry_z_.span(entries_)});
}

std::uint32_t SlicesExtractor::owner_of(std::uint64_t key) const {
    std::uint32_t i = 0, j = 0, k = 0, axis = 0;
    edge_key_corner(key, i, j, k, axis);
    const std::uint32_t oi = std::min(grid_.block_of(i), grid_.bx - 1),
                        oj = std::min(grid_.block_of(j), grid_.by - 1),
                        ok = std::min(grid_.block_of(k), grid_.bz - 1);
    return (ok * grid_.by + oj) * grid_.bx + oi;
}

void SlicesExtractor::extract_block(std::uint32_t scheduled) {
    const std::uint32_t item = schedule_[scheduled];
    const std::uint32_t b = active_[item];
    const std::uint32_t bi = b % grid_.bx, bj = (b / grid_.bx) % grid_.by, bk = b / (grid_.bx * grid_.by);
    const std::uint32_t first = block_offsets_[b], np = block_offsets_[b + 1] - first;
    const ConstPositions particles{entry_x_.span(entries_).subspan(first, np),
                                   entry_y_.span(entries_).subspan(first, np),
                                   entry_z_.span(entries_).subspan(first, np)};
    Scratch& s = acquire_scratch();
    struct Release {
        SlicesExtractor* self;
        Scratch& s;
        ~Release() { self->release_scratch(s); }
    } release{this, s};

    // Lookup cache (grown and rebuilt if this block lists more column entries than ever before).
    ensure(s.order, np), ensure(s.mids, np);
    ensure(s.rows, std::size_t(np) * lookup_row_slots(grid_));
    const std::size_t offset_slots = lookup_offset_slots(grid_);
    ensure(s.sort_counts, lookup_sort_slots(grid_)), ensure(s.column_offsets, offset_slots);
    const LookupScratch ls{s.order.span(np), s.mids.span(np), s.sort_counts.span(lookup_sort_slots(grid_)),
                           s.rows.span(std::size_t(np) * lookup_row_slots(grid_))};
    const std::uint32_t groups = lookup_groups(grid_), columns = (grid_.n + 1) * (grid_.n + 1);
    const std::span<const std::uint32_t> ids = block_entries_.span(entries_).subspan(first, np);
    const ConstKernelShapes shapes = kernel_shapes();
    auto build = [&](auto& entries, auto&& builder) {
        std::uint32_t need = builder(entries.span(entries.capacity()));
        if (need > entries.capacity()) {
            ensure(entries, need);
            need = builder(entries.span(entries.capacity()));
        }
        return need;
    };
    const bool aniso = settings_.anisotropy > 0;
    const std::uint32_t need =
        aniso ? build(s.aniso_entries,
                      [&](std::span<AnisoEntry> e) {
                          return build_aniso_lookup_cache(grid_, bi, bj, bk, particles, ids, shapes, ls,
                                                          s.column_offsets.span(offset_slots), e);
                      })
              : build(s.entries, [&](std::span<ColumnEntry> e) {
                    return build_lookup_cache(grid_, bi, bj, bk, particles, ls,
                                              s.column_offsets.span(offset_slots), e);
                });
    const LookupCacheView cache{s.column_offsets.span(offset_slots), s.entries.span(aniso ? 0 : need),
                                grid_.reach, groups, columns};
    const AnisoLookupCacheView aniso_cache{s.column_offsets.span(offset_slots),
                                           s.aniso_entries.span(aniso ? need : 0), grid_.reach, groups,
                                           columns};
    slots_[item].particles = np, slots_[item].cache_entries = need;

    // Neighbours that list no particle: their shared face carries no surface (march_block). Faces shared
    // with a non-empty neighbour are scanned once for both; the face's slot belongs to the block on its
    // +axis side.
    unsigned empty_neighbours = 0;
    SharedFaces shared{};
    const std::size_t face_size = SliceScratchSizes(grid_.n).face_bits;  // words of one face
    auto shared_face = [&](std::uint32_t plus_side_item, std::uint32_t a) {
        const std::size_t at = std::size_t(plus_side_item) * 3 + a;
        return SharedFace{face_state_.data() + at, face_bits_.data() + at * face_size};
    };
    const std::uint32_t bidx[3] = {bi, bj, bk}, nb[3] = {grid_.bx, grid_.by, grid_.bz},
                        stride[3] = {1, grid_.bx, grid_.bx * grid_.by};
    for (std::uint32_t a = 0; a < 3; ++a)
        for (std::uint32_t side = 0; side < 2; ++side) {
            if (side == 0 ? bidx[a] == 0 : bidx[a] + 1 == nb[a])
                continue;  // grid boundary: march_block knows
            const std::uint32_t o = side == 0 ? b - stride[a] : b + stride[a];
            if (block_to_active_[o] < 0) {
                empty_neighbours |= 1u << (2 * a + side);
                continue;
            }
            shared[2 * a + side] =
                shared_face(side == 0 ? item : static_cast<std::uint32_t>(block_to_active_[o]), a);
        }

    // The sweep (run again with more room in the rare case the block's mesh outgrew its buffers).
    BlockSlot& slot = slots_[item];
    const SliceScratch scratch = s.view(grid_);
    auto grow = [&slot](std::size_t vertices, std::size_t triangles) {
        slot.positions.reserve(4 * vertices), slot.triangles.reserve(3 * triangles);
        slot.border.reserve(vertices), slot.foreign.reserve(vertices);
    };
    if (slot.positions.capacity() == 0) grow(1024, 2048);
    for (;;) {
        const std::size_t room = slot.border.capacity();
        const BlockMeshOut mesh{slot.positions.span(4 * room), slot.triangles.span(slot.triangles.capacity()),
                                slot.border.span(room), slot.foreign.span(room)};
        const BlockSweepContext block{
            &grid_,           bi,    bj, bk, iso_, particles, scratch, mesh, settings_.exhaustive_seeds,
            empty_neighbours, shared};
        slot.sweep = aniso ? march_block(block, aniso_cache) : march_block(block, cache);
        if (!slot.sweep.overflow) break;
        grow(2 * room, 2 * slot.triangles.capacity() / 3);
    }
    slot.capacity = static_cast<std::uint32_t>(slot.border.capacity());
    slot.triangles_n = slot.sweep.triangles;
    slot.owned = slot.sweep.owned;
    slot.border_n = slot.sweep.border;
    slot.foreign_n = slot.sweep.foreign;
    ensure(slot.foreign_owner, slot.foreign_n), ensure(slot.foreign_mesh, slot.foreign_n);
    ensure(slot.acc, std::size_t(slot.capacity) * 4);
    // The neighbours look this block's border vertices up by key.
    std::sort(slot.border.data(), slot.border.data() + slot.border_n,
              [](const KeyedVertex& x, const KeyedVertex& y) { return x.key < y.key; });
}

void SlicesExtractor::weld_offsets(SurfaceMesh& out) {
    std::uint64_t vertices = 0, triangles = 0;
    std::uint32_t most_particles = 0, most_entries = 0;
    for (std::uint32_t a = 0; a < active_count_; ++a) {
        BlockSlot& s = slots_[a];
        most_particles = std::max(most_particles, s.particles);
        most_entries = std::max(most_entries, s.cache_entries);
        s.vertex_offset = vertices, s.triangle_offset = triangles;
        vertices += s.owned, triangles += s.triangles_n;
        stats_.seeds += s.sweep.seeds, stats_.cubes += s.sweep.cubes,
            stats_.slice_fills += s.sweep.slice_fills;
        stats_.peak_slices = std::max(stats_.peak_slices, s.sweep.peak_slices);
    }
    grow_scratch(most_particles, most_entries);
    if (triangles > settings_.max_triangles)
        throw std::length_error(fmt::format("marching slices: {} triangles exceed the limit of {}", triangles,
                                            settings_.max_triangles));
    if (vertices >= std::numeric_limits<std::uint32_t>::max())
        throw std::length_error("marching slices: more than 2^32 vertices");
    ensure(out.vertices6, std::size_t(vertices) * 6);
    ensure(out.indices, std::size_t(triangles) * 3);
    out.vertex_count = vertices;
    out.index_count = triangles * 3;
    stats_.vertices = vertices, stats_.triangles = triangles;
}

void SlicesExtractor::weld_block(std::uint32_t item, SurfaceMesh& out) {
    BlockSlot& s = slots_[item];
    for (std::uint32_t q = 0; q < s.foreign_n; ++q) {
        const KeyedVertex& fv = s.foreign[q];
        const std::int32_t owner = block_to_active_[owner_of(fv.key)];
        const BlockSlot* o = owner >= 0 ? &slots_[std::size_t(owner)] : nullptr;
        const KeyedVertex* it = nullptr;
        if (o) {
            it = std::lower_bound(o->border.data(), o->border.data() + o->border_n, fv.key,
                                  [](const KeyedVertex& e, std::uint64_t k) { return e.key < k; });
            if (it == o->border.data() + o->border_n || it->key != fv.key) it = nullptr;
        }
        if (!it && fixed_frame_) {  // the owner lies beyond the piece's particles: a rim block's vertex
            s.foreign_owner[q] = {kMissingVertex, 0};
            s.foreign_mesh[q] = kMissingVertex;
            continue;
        }
        if (!it)
            throw std::logic_error(fmt::format(
                "marching slices: block {} refers to a border vertex its owner block did not produce",
                active_[item]));
        s.foreign_owner[q] = {static_cast<std::uint32_t>(owner), it->index};
        s.foreign_mesh[q] = static_cast<std::uint32_t>(o->vertex_offset) + it->index;
    }
    const BlockVertexMap map{s.owned, static_cast<std::uint32_t>(s.vertex_offset), s.capacity - 1,
                             s.foreign_mesh.span(s.foreign_n)};
    const std::size_t corners = std::size_t(s.triangles_n) * 3;
    weld_indices(s.triangles.span(corners), map, {out.indices.data() + s.triangle_offset * 3, corners});
}

void SlicesExtractor::normals_block(std::uint32_t item) {
    BlockSlot& s = slots_[item];
    const std::size_t foreign_from = std::size_t(s.capacity - s.foreign_n) * 4;
    std::fill(s.acc.data(), s.acc.data() + std::size_t(s.owned) * 4, 0.0f);
    std::fill(s.acc.data() + foreign_from, s.acc.data() + std::size_t(s.capacity) * 4, 0.0f);
    accumulate_angle_normals(s.positions.span(std::size_t(s.capacity) * 4),
                             s.triangles.span(std::size_t(s.triangles_n) * 3),
                             s.acc.span(std::size_t(s.capacity) * 4));
}

void SlicesExtractor::borders() {
    for (std::uint32_t a = 0; a < active_count_; ++a) {  // border contributions, in block order
        const BlockSlot& s = slots_[a];
        for (std::uint32_t q = 0; q < s.foreign_n; ++q) {
            if (s.foreign_owner[q].item == kMissingVertex) continue;
            const float* from = s.acc.data() + std::size_t(s.foreign[q].index) * 4;
            float* to =
                slots_[s.foreign_owner[q].item].acc.data() + std::size_t(s.foreign_owner[q].vertex) * 4;
            for (std::size_t c = 0; c < 3; ++c) to[c] += from[c];
        }
    }
}

void SlicesExtractor::stage(std::uint32_t item, SurfaceMesh& out) {
    const BlockSlot& s = slots_[item];
    write_vertices(s.positions.span(std::size_t(s.owned) * 4), s.acc.span(std::size_t(s.owned) * 4),
                   {out.vertices6.data() + s.vertex_offset * 6, std::size_t(s.owned) * 6});
}

void SlicesExtractor::extract_serial(ConstPositions p, SurfaceMesh& out) {
    begin_frame(p);
    for (std::uint32_t c = 0; c < shape_chunks(); ++c) shape(p, c);
    for (std::uint32_t c = 0; c < chunks_; ++c) block_count(p, c);
    block_prefix();
    for (std::uint32_t c = 0; c < chunks_; ++c) block_scatter(p, c);
    for (std::uint32_t a = 0; a < blocks(); ++a) extract_block(a);
    weld_offsets(out);
    for (std::uint32_t a = 0; a < blocks(); ++a) weld_block(a, out);
    for (std::uint32_t a = 0; a < blocks(); ++a) normals_block(a);
    borders();
    for (std::uint32_t a = 0; a < blocks(); ++a) stage(a, out);
}

}  // namespace rivulet
