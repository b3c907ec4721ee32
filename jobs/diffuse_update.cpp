#include "jobs/diffuse_update.h"

#include <algorithm>
#include <atomic>

#include "jobs/counter_rng.h"

namespace rivulet {
namespace {

void add_density(std::span<std::uint32_t> density, std::uint32_t voxel, std::uint32_t delta) {
    // Integer adds commute, so the counts end the same whatever order the threads run in.
    std::atomic_ref<std::uint32_t>(density[voxel]).fetch_add(delta, std::memory_order_relaxed);
}

constexpr int kCollisionRounds = 3;

// The step p0 -> p against one collider, in the collider's frame, so a moving collider pushes the
// particles it sweeps over.
bool collide_one(const DiffuseColliderStep& c, float dt, float restitution, Vec3f p0, Vec3f& p, Vec3f& v) {
    const Vec3f lo{std::min(p0.x, p.x), std::min(p0.y, p.y), std::min(p0.z, p.z)};
    const Vec3f hi{std::max(p0.x, p.x), std::max(p0.y, p.y), std::max(p0.z, p.z)};
    if (hi.x < c.swept_min.x || hi.y < c.swept_min.y || hi.z < c.swept_min.z || lo.x > c.swept_max.x ||
        lo.y > c.swept_max.y || lo.z > c.swept_max.z)
        return false;
    const Vec3f cv = (c.offset1 - c.offset0) * (1 / dt);
    Vec3f local1 = p - c.offset1, rel = v - cv;
    if (!c.collide(c.mesh, p0 - c.offset0, local1, rel, restitution)) return false;
    p = local1 + c.offset1;
    v = rel + cv;
    return true;
}

}  // namespace

void diffuse_update_block(std::size_t block, const DiffuseUpdateContext& ctx) {
    const ParticleSpans& P = ctx.particles;
    const DiffuseAttributeSpans& A = ctx.attributes;
    const std::size_t begin = block * ctx.block_size;
    const std::size_t end = std::min(P.size(), begin + ctx.block_size);
    std::uint32_t* dead = ctx.dead.data() + block * ctx.block_size;
    std::uint32_t dead_n = 0;
    // An active voxel: inside the mesh and not overlapped by a collider this step.
    const auto active = [&](std::uint32_t v) {
        return v != kOutsideVoxel && ctx.material[v] != kNoMaterial && ctx.blocked[v] == 0;
    };
    for (std::size_t i = begin; i < end; ++i) {
        Vec3f p{P.x[i], P.y[i], P.z[i]}, v{P.vx[i], P.vy[i], P.vz[i]};
        const Vec3f p0 = p;
        const std::uint32_t old_voxel = A.voxel[i];
        Vec3f accel = ctx.accel;
        if (ctx.dissolve.active()) {
            // Each particle its own place in the front's band and its own gust, so the shape breaks up
            // rather than sliding away whole.
            const std::uint64_t h = mix64(P.id[i]);
            const float ragged = float(h >> 40) * (1.0f / 16777216.0f);
            const float gust = 0.3f + 1.4f * float((h >> 16) & 0xffffffu) * (1.0f / 16777216.0f);
            if (ctx.dissolve.behind(p - ctx.offset, ragged)) accel = accel + ctx.dissolve.wind * gust;
        }
        if (active(old_voxel)) {
            const VoxelMaterial& m = ctx.materials[ctx.material[old_voxel]];
            const bool centred = m.force.kind >= 2;  // spiral, orbit, helix
            const Vec3f centre =
                centred ? (m.about_region ? m.region_centre : ctx.grid.voxel_centre(old_voxel)) + ctx.offset
                        : Vec3f{};
            apply_voxel_step(m.step, centre, accel, p, v);
        } else {
            apply_voxel_step(ctx.outside, {}, accel, p, v);
        }
        // A moving solid may push a particle into another one, so the tests repeat while they bounce;
        // still solids come last in each round and so always have the final word.
        for (int round = 0; round < kCollisionRounds; ++round) {
            bool hit = false;
            for (int still = 0; still < 2; ++still)
                for (const DiffuseColliderStep& c : ctx.colliders)
                    if ((c.offset0 == c.offset1) == (still == 1))
                        hit |= collide_one(c, ctx.dt, ctx.restitution, p0, p, v);
            if (!hit) break;
        }
        P.x[i] = p.x, P.y[i] = p.y, P.z[i] = p.z;
        P.vx[i] = v.x, P.vy[i] = v.y, P.vz[i] = v.z;

        std::uint32_t voxel = ctx.grid.voxel_of(p - ctx.offset);
        if (!active(voxel)) voxel = kOutsideVoxel;
        const float t0 = A.duration[i] > 0 ? std::min(1.0f, A.elapsed[i] / A.duration[i]) : 1.0f;
        if (voxel != old_voxel) {
            if (old_voxel != kOutsideVoxel) add_density(ctx.density, old_voxel, ~0u);
            const std::uint32_t now_rgba = lerp_rgba(A.from_rgba[i], A.to_rgba[i], t0);
            const float now_size = A.from_size[i] + (A.to_size[i] - A.from_size[i]) * t0;
            if (voxel != kOutsideVoxel) {
                // Entering a voxel (re-entering included: the fade stops, life goes on).
                add_density(ctx.density, voxel, 1);
                const VoxelMaterial& m = ctx.materials[ctx.material[voxel]];
                A.from_rgba[i] = now_rgba, A.to_rgba[i] = ctx.voxel_rgba[voxel];
                A.from_size[i] = now_size, A.to_size[i] = m.size;
                A.elapsed[i] = 0, A.duration[i] = m.interpolation_time;
                A.fading[i] = 0;
            } else if (!A.fading[i]) {
                // Leaving the active voxels: fade by the last voxel's fading attributes (§4.3).
                const std::uint16_t mi = old_voxel != kOutsideVoxel ? ctx.material[old_voxel] : kNoMaterial;
                const VoxelMaterial& m = ctx.materials[mi == kNoMaterial ? 0 : mi];
                A.from_rgba[i] = now_rgba;
                A.to_rgba[i] =
                    m.fade_color_set ? m.fade_rgba : (now_rgba & 0x00ffffffu) | (m.fade_rgba & 0xff000000u);
                A.from_size[i] = now_size, A.to_size[i] = m.fade_size;
                A.elapsed[i] = 0, A.duration[i] = m.lifetime;
                A.fading[i] = 1;
            }
            A.voxel[i] = voxel;
        }
        // A settled particle (interpolation done, not fading) keeps its colour and size: no lerp, and
        // its clock need not run, so its attributes are only read.
        const float elapsed = A.elapsed[i];
        if (A.fading[i] || elapsed < A.duration[i]) {
            A.elapsed[i] = elapsed + ctx.dt;
            const float t = A.duration[i] > 0 ? std::min(1.0f, A.elapsed[i] / A.duration[i]) : 1.0f;
            A.sprite[i] = {p.x, p.y, p.z, A.from_size[i] + (A.to_size[i] - A.from_size[i]) * t,
                           lerp_rgba(A.from_rgba[i], A.to_rgba[i], t)};
        } else {
            A.sprite[i] = {p.x, p.y, p.z, A.to_size[i], A.to_rgba[i]};
        }
        if (A.fading[i] && A.elapsed[i] >= A.duration[i]) dead[dead_n++] = static_cast<std::uint32_t>(i);
    }
    ctx.dead_count[block] = dead_n;
}

}  // namespace rivulet
