#include "systems/diffuse/diffuse_simulation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "systems/diffuse/solid_collider.h"

namespace rivulet {
namespace {

constexpr std::size_t kUpdateBlock = 16384;
// Voxels per emission block. Births are granted in voxel order until the room runs out, so when room is
// short they crowd into the first few blocks; small blocks spread them over both threads.
constexpr std::size_t kEmitBlock = 512;
constexpr std::size_t kFillBlock = 4096;  // places filled per compact_fill block

SolidCollider make_collider(const DiffuseCollider& c) {
    if (c.shape == "sphere") return SolidCollider::sphere(c.radius);
    if (c.shape == "box") return SolidCollider::box(c.half_extents);
    return SolidCollider::mesh(load_diffuse_mesh(c.mesh, 1, {}));
}

}  // namespace

Vec3f diffuse_collider_position(const DiffuseCollider& c, double t) {
    if (c.period <= 0) return c.from;
    const double phase = 0.5 - 0.5 * std::cos(2 * std::numbers::pi * t / double(c.period));
    return c.from + (c.to - c.from) * static_cast<float>(phase);
}

DiffuseSimulation::DiffuseSimulation(const SceneDesc& scene, ParticleSet& particles) : scene_(scene) {
    const DiffuseDesc& d = scene_.diffuse;
    object_ = build_voxel_object(d, load_diffuse_mesh(d.mesh, d.scale, d.position), scene_.dt);
    step_table_ = make_diffuse_step_table(object_.materials, make_voxel_step(VoxelForce{}, 0, scene_.dt));
    grid_ = {object_.shape.origin, object_.shape.cell, object_.shape.nx, object_.shape.ny, object_.shape.nz};
    density_.assign(object_.shape.count(), 0);
    column_.resize(object_.shape.count());
    for (std::size_t v = 0; v < column_.size(); ++v)
        column_[v] = diffuse_voxel_column(object_.material[v], false, object_.materials.size());
    for (const DiffuseCollider& c : d.colliders) colliders_.push_back(make_collider(c));
    steps_.resize(colliders_.size());
    for (std::size_t c = 0; c < colliders_.size(); ++c) {
        DiffuseColliderStep& s = steps_[c];
        s.solid = &colliders_[c];
        s.collide = SolidCollider::collide_step;
        s.reach_centre = colliders_[c].reach_centre();
        s.reach_radius = colliders_[c].reach_radius();
    }
    blocked_ranges_.assign(colliders_.size(), {0, -1, 0, -1, 0, -1});
    const std::size_t cap = scene_.max_particles;
    particles.reserve(cap);
    for (auto* a : {&voxel_, &from_rgba_, &to_rgba_}) a->reserve(cap);
    for (auto* a : {&from_size_, &to_size_, &elapsed_, &duration_}) a->reserve(cap);
    for (AlignedArray<DiffuseSprite>& s : sprite_) s.reserve(cap);
    depth_key_.reserve(cap);
    depth_map_ = diffuse_depth_map(scene_.camera);
    const std::size_t blocks = diffuse_update_blocks(cap, kUpdateBlock);
    dead_.assign(blocks * kUpdateBlock, 0);
    dead_count_.assign(blocks, 0);
    moves_.assign(2 * blocks * kUpdateBlock, 0);
    move_count_.assign(blocks, 0);
    dead_all_.reserve(cap);
    born_.reserve(cap);
    fills_.reserve(2 * cap);
    emit_counts_.assign(diffuse_emit_blocks(object_.inside.size(), kEmitBlock), 0);
    emit_offsets_.assign(emit_counts_.size(), 0);
}

DiffuseSimulation::~DiffuseSimulation() = default;

DiffuseAttributeSpans DiffuseSimulation::attributes(std::size_t n) {
    return {voxel_.span(n),    from_rgba_.span(n), to_rgba_.span(n),  from_size_.span(n),
            to_size_.span(n),  elapsed_.span(n),   duration_.span(n), sprite_[sprite_buffer_].span(n),
            depth_key_.span(n)};
}

std::span<const DiffuseSprite> DiffuseSimulation::sprites() const {
    return sprite_[sprite_buffer_].span(sprites_);
}

std::span<const std::uint32_t> DiffuseSimulation::depth_keys() const {
    return depth_key_.span(sprites_);
}

DepthKeyMap diffuse_depth_map(const CameraDesc& camera) {
    // The scene's camera is fixed: the depth range of a ball around its target that holds the object and
    // the particles drifting out of its grid while they fade (farther ones clamp, still drawn, in a tie).
    constexpr float kReach = 4.0f;
    DepthKeyMap map;
    map.origin = camera.eye;
    map.direction = normalize(camera.target - camera.eye);
    const float to_target = length(camera.target - camera.eye);
    map.depth_min = std::max(0.0f, to_target - kReach);
    map.depth_max = to_target + kReach;
    return map;
}

void DiffuseSimulation::begin_frame(ParticleSet& particles, std::uint64_t frame, Vec3f offset) {
    frame_ = frame;
    sprite_buffer_ = (sprite_buffer_ + 1) % kSpriteBuffers;
    sprites_ = particles.size();
    const float dt = scene_.dt;
    prev_offset_ = first_frame_ ? offset : offset_;
    offset_ = offset;
    velocity_ = (offset_ - prev_offset_) * (1 / dt);
    first_frame_ = false;
    const double t0 = double(frame) * dt, t1 = double(frame + 1) * dt;
    for (std::size_t c = 0; c < colliders_.size(); ++c) {
        DiffuseColliderStep& s = steps_[c];
        s.offset0 = diffuse_collider_position(scene_.diffuse.colliders[c], t0);
        s.offset1 = diffuse_collider_position(scene_.diffuse.colliders[c], t1);
        const Vec3f lo = colliders_[c].bounds_min(), hi = colliders_[c].bounds_max();
        s.swept_min = {std::min(s.offset0.x, s.offset1.x) + lo.x, std::min(s.offset0.y, s.offset1.y) + lo.y,
                       std::min(s.offset0.z, s.offset1.z) + lo.z};
        s.swept_max = {std::max(s.offset0.x, s.offset1.x) + hi.x, std::max(s.offset0.y, s.offset1.y) + hi.y,
                       std::max(s.offset0.z, s.offset1.z) + hi.z};
    }
    block_voxels();
    const DissolveDesc& w = scene_.diffuse.dissolve;
    dissolve_ = {};
    if (w.start >= 0 && t1 > w.start) {
        dissolve_.direction = normalize(w.wind);
        dissolve_.wind = w.wind;
        // The front starts at the object's upwind corner of its grid.
        float upwind = 3.0e38f;
        for (int corner = 0; corner < 8; ++corner) {
            const Vec3f c =
                grid_.origin + Vec3f{corner & 1 ? float(grid_.nx) : 0, corner & 2 ? float(grid_.ny) : 0,
                                     corner & 4 ? float(grid_.nz) : 0} *
                                   grid_.cell;
            upwind = std::min(upwind, dot(c, dissolve_.direction));
        }
        dissolve_.band = 8 * grid_.cell;
        dissolve_.front = w.front_speed > 0 ? upwind + w.front_speed * float(t1 - w.start) : 3.0e38f;
    }
}

// §5.2: a collider inside the object's box deactivates the voxels it overlaps, so no particle is born
// inside it and those in them fade unless they leave.
void DiffuseSimulation::block_voxels() {
    for (const auto& r : blocked_ranges_)
        for (int iz = r[4]; iz <= r[5]; ++iz)
            for (int iy = r[2]; iy <= r[3]; ++iy)
                for (int ix = r[0]; ix <= r[1]; ++ix) {
                    const std::size_t v = object_.shape.index(ix, iy, iz);
                    column_[v] = diffuse_voxel_column(object_.material[v], false, object_.materials.size());
                }
    const float inv = 1 / grid_.cell;
    for (std::size_t c = 0; c < colliders_.size(); ++c) {
        // Object space of the step's end: where the particles look their voxels up.
        const Vec3f at = steps_[c].offset1 - offset_;
        const Vec3f lo = colliders_[c].bounds_min() + at - grid_.origin;
        const Vec3f hi = colliders_[c].bounds_max() + at - grid_.origin;
        auto& r = blocked_ranges_[c];
        r = {std::max(0, int(std::floor(lo.x * inv))), std::min(grid_.nx - 1, int(std::floor(hi.x * inv))),
             std::max(0, int(std::floor(lo.y * inv))), std::min(grid_.ny - 1, int(std::floor(hi.y * inv))),
             std::max(0, int(std::floor(lo.z * inv))), std::min(grid_.nz - 1, int(std::floor(hi.z * inv)))};
        for (int iz = r[4]; iz <= r[5]; ++iz)
            for (int iy = r[2]; iy <= r[3]; ++iy)
                for (int ix = r[0]; ix <= r[1]; ++ix) {
                    const std::size_t v = object_.shape.index(ix, iy, iz);
                    if (object_.material[v] == kNoMaterial) continue;
                    const Vec3f vmin =
                        grid_.origin + Vec3f{float(ix), float(iy), float(iz)} * grid_.cell - at;
                    if (colliders_[c].overlaps_box(vmin, vmin + Vec3f{1, 1, 1} * grid_.cell))
                        column_[v] =
                            diffuse_voxel_column(object_.material[v], true, object_.materials.size());
                }
    }
}

DiffuseUpdateContext DiffuseSimulation::update_context(ParticleSet& particles) {
    DiffuseUpdateContext ctx;
    ctx.particles = particles.spans();
    ctx.attributes = attributes(particles.size());
    ctx.grid = grid_;
    ctx.offset = offset_;
    ctx.material = object_.material;
    ctx.voxel_rgba = object_.rgba;
    ctx.materials = object_.materials;
    ctx.column = column_;
    ctx.density = density_;
    ctx.colliders = steps_;
    ctx.accel = scene_.gravity;
    ctx.dissolve = dissolve_;
    ctx.depth_map = depth_map_;
    ctx.steps = step_table_;
    ctx.restitution = scene_.restitution;
    ctx.dt = scene_.dt;
    ctx.block_size = kUpdateBlock;
    ctx.dead = dead_;
    ctx.dead_count = dead_count_;
    ctx.moves = moves_;
    ctx.move_count = move_count_;
    ctx.born = born_;
    return ctx;
}

std::size_t DiffuseSimulation::phase_blocks(std::size_t phase, const ParticleSet& particles) const {
    if (!kPhases[phase].parallel) return 1;
    if (phase == kUpdate) return update_blocks(particles);
    return phase == kCompactFill ? fill_blocks() : emit_blocks();
}

void DiffuseSimulation::run_phase(std::size_t phase, std::size_t block, ParticleSet& particles) {
    switch (phase) {
        case kUpdate:
            return update_block(block, particles);
        case kCompact:
            return compact(particles);
        case kCompactFill:
            return fill_block(block, particles);
        case kEmitCount:
            return emit_count_block(block, particles);
        case kEmitOffsets:
            return emit_offsets(particles);
        case kEmit:
            return emit_block(block, particles);
        default:
            throw std::out_of_range("DiffuseSimulation::run_phase: no phase " + std::to_string(phase));
    }
}

void DiffuseSimulation::run_phases_serial(ParticleSet& particles) {
    for (std::size_t p = 0; p < kPhaseCount; ++p)
        for (std::size_t b = 0, n = phase_blocks(p, particles); b < n; ++b) run_phase(p, b, particles);
}

std::size_t DiffuseSimulation::update_blocks(const ParticleSet& particles) const {
    return diffuse_update_blocks(particles.size(), kUpdateBlock);
}

void DiffuseSimulation::update_block(std::size_t block, ParticleSet& particles) {
    diffuse_update_block(block, update_context(particles));
}

void DiffuseSimulation::compact(ParticleSet& particles) {
    diffuse_apply_moves(update_context(particles), update_blocks(particles));
    dead_all_.clear();
    for (std::size_t b = 0; b < update_blocks(particles); ++b)
        dead_all_.insert(dead_all_.end(), dead_.begin() + std::ptrdiff_t(b * kUpdateBlock),
                         dead_.begin() + std::ptrdiff_t(b * kUpdateBlock + dead_count_[b]));
    compact_from_ = particles.size();
    births_in_place_ = 0;  // until emit_offsets knows the births
}

std::size_t DiffuseSimulation::fill_blocks() const {
    return (fills_.size() / 2 + kFillBlock - 1) / kFillBlock;
}

// The count has already shrunk (emit_offsets): the spans reach back to the particles being moved.
void DiffuseSimulation::fill_block(std::size_t block, ParticleSet& particles) {
    ParticleSpans p = particles.spans_over(compact_from_);
    DiffuseAttributeSpans a = attributes(compact_from_);
    const std::size_t end = std::min(fills_.size() / 2, (block + 1) * kFillBlock);
    for (std::size_t k = block * kFillBlock; k < end; ++k) {
        const std::size_t from = fills_[2 * k], to = fills_[2 * k + 1];
        p.x[to] = p.x[from], p.y[to] = p.y[from], p.z[to] = p.z[from];
        p.vx[to] = p.vx[from], p.vy[to] = p.vy[from], p.vz[to] = p.vz[from], p.id[to] = p.id[from];
        a.voxel[to] = a.voxel[from], a.from_rgba[to] = a.from_rgba[from], a.to_rgba[to] = a.to_rgba[from];
        a.from_size[to] = a.from_size[from], a.to_size[to] = a.to_size[from];
        a.elapsed[to] = a.elapsed[from], a.duration[to] = a.duration[from];
    }
}

DiffuseEmitContext DiffuseSimulation::emit_context(ParticleSet& particles) {
    DiffuseEmitContext ctx;
    ctx.inside = object_.inside;
    ctx.material = object_.material;
    ctx.voxel_rgba = object_.rgba;
    ctx.materials = object_.materials;
    ctx.column = column_;
    ctx.density = density_;
    ctx.grid = grid_;
    ctx.offset = offset_;
    ctx.object_velocity = velocity_;
    ctx.dissolve = dissolve_;
    ctx.block_size = kEmitBlock;
    ctx.counts = emit_counts_;
    ctx.offsets = emit_offsets_;
    ctx.particles = particles.spans();
    ctx.attributes = attributes(particles.size());
    ctx.places = std::span<const std::uint32_t>(dead_all_).first(births_in_place_);
    ctx.first = emit_first_;
    ctx.first_id = birth_first_id_;
    ctx.seed = scene_.seed;
    ctx.frame = frame_;
    return ctx;
}

void DiffuseSimulation::emit_count_block(std::size_t block, ParticleSet& particles) {
    diffuse_emit_count_block(block, emit_context(particles));
}

// The births take the dead's places, lowest first; the dead's places left over are filled from the end
// (compact_fill), or the births left over go after the live particles. Every place filled from the end
// lies below the new count and every particle moved at or above it, so fills and births never meet.
void DiffuseSimulation::emit_offsets(ParticleSet& particles) {
    const std::size_t dead = dead_all_.size(), live = compact_from_ - dead;
    const std::size_t births = diffuse_emit_offsets(emit_context(particles), particles.capacity() - live);
    births_in_place_ = std::min(births, dead);
    fills_.clear();
    emit_first_ =
        fill_dead_from_end(compact_from_, std::span<const std::uint32_t>(dead_all_).subspan(births_in_place_),
                           [&](std::size_t from, std::size_t to) {
                               fills_.push_back(static_cast<std::uint32_t>(from));
                               fills_.push_back(static_cast<std::uint32_t>(to));
                           });
    particles.resize(emit_first_ + (births - births_in_place_));
    // The next update sets the births' interpolation state (DiffuseUpdateContext::born): the dead's
    // places they take, then those after the live particles, ascending.
    born_.assign(dead_all_.begin(), dead_all_.begin() + std::ptrdiff_t(births_in_place_));
    for (std::size_t k = emit_first_; k < particles.size(); ++k)
        born_.push_back(static_cast<std::uint32_t>(k));
    birth_first_id_ = next_id_;
    next_id_ += static_cast<std::uint32_t>(births);
}

void DiffuseSimulation::emit_block(std::size_t block, ParticleSet& particles) {
    diffuse_emit_block(block, emit_context(particles));
}

}  // namespace rivulet
