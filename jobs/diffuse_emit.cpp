#include "jobs/diffuse_emit.h"

#include <algorithm>

#include "jobs/counter_rng.h"

namespace rivulet {
namespace {

constexpr std::size_t kPrefetchBirths = 16;

std::uint32_t wanted(std::uint32_t v, const DiffuseEmitContext& ctx) {
    if (ctx.column[v] == ctx.materials.size()) return 0;  // no particle may appear inside a solid (§5.2)
    if (ctx.dissolve.active() &&
        ctx.dissolve.behind(ctx.grid.voxel_centre(v), float(mix64(v) >> 40) * (1.0f / 16777216.0f)))
        return 0;
    const VoxelMaterial& m = ctx.materials[ctx.material[v]];
    const std::uint32_t have = ctx.density[v];
    return have >= m.max_density ? 0 : std::min<std::uint32_t>(m.max_density - have, m.emit_per_frame);
}

}  // namespace

void diffuse_emit_count_block(std::size_t block, const DiffuseEmitContext& ctx) {
    const std::size_t begin = block * ctx.block_size,
                      end = std::min(ctx.inside.size(), begin + ctx.block_size);
    std::uint32_t n = 0;
    for (std::size_t k = begin; k < end; ++k) n += wanted(ctx.inside[k], ctx);
    ctx.counts[block] = n;
}

std::size_t diffuse_emit_offsets(const DiffuseEmitContext& ctx, std::size_t room) {
    std::size_t total = 0;
    for (std::size_t b = 0; b < ctx.counts.size(); ++b) {
        const std::size_t granted = std::min<std::size_t>(ctx.counts[b], room - total);
        ctx.offsets[b] = static_cast<std::uint32_t>(total);
        ctx.counts[b] = static_cast<std::uint32_t>(granted);
        total += granted;
    }
    return total;
}

void diffuse_emit_block(std::size_t block, const DiffuseEmitContext& shared) {
    // A copy whose address never escapes: read through the reference, every field would be read again
    // after each store to a particle array (the compiler cannot rule out that they overlap).
    const DiffuseEmitContext ctx = shared;
    const std::size_t begin = block * ctx.block_size,
                      end = std::min(ctx.inside.size(), begin + ctx.block_size);
    std::uint32_t left = ctx.counts[block];
    std::size_t birth = ctx.offsets[block];
    const ParticleSpans& P = ctx.particles;
    const DiffuseAttributeSpans& A = ctx.attributes;
    for (std::size_t k = begin; k < end && left > 0; ++k) {
        const std::uint32_t v = ctx.inside[k];
        const std::uint32_t n = std::min(wanted(v, ctx), left);
        if (n == 0) continue;
        const VoxelMaterial& m = ctx.materials[ctx.material[v]];
        const Vec3f corner = ctx.grid.voxel_min(v) + ctx.offset;
        for (std::uint32_t j = 0; j < n; ++j, ++birth) {
            // The places of later births are scattered over the arrays: ask for their lines early.
            if (const std::size_t ahead = birth + kPrefetchBirths; ahead < ctx.places.size()) {
                const std::uint32_t at = ctx.places[ahead];
                for (float* a : {&P.x[at], &P.y[at], &P.z[at], &P.vx[at], &P.vy[at], &P.vz[at]})
                    __builtin_prefetch(a, 1);
                __builtin_prefetch(&P.id[at], 1), __builtin_prefetch(&A.voxel[at], 1);
            }
            const std::size_t out =
                birth < ctx.places.size() ? ctx.places[birth] : ctx.first + (birth - ctx.places.size());
            const std::uint32_t id = ctx.first_id + static_cast<std::uint32_t>(birth);
            const auto u = [&](std::uint64_t stream) {
                return counter_uniform(ctx.seed, ctx.frame, id, stream);
            };
            P.x[out] = corner.x + u(0) * ctx.grid.cell;
            P.y[out] = corner.y + u(1) * ctx.grid.cell;
            P.z[out] = corner.z + u(2) * ctx.grid.cell;
            P.vx[out] = ctx.object_velocity.x + (2 * u(3) - 1) * m.jitter;
            P.vy[out] = ctx.object_velocity.y + (2 * u(4) - 1) * m.jitter;
            P.vz[out] = ctx.object_velocity.z + (2 * u(5) - 1) * m.jitter;
            P.id[out] = id;
            // Born transparent, the particle fades in over the voxel's interpolation time: the next
            // update sets that state from the voxel (DiffuseUpdateContext::born).
            A.voxel[out] = v;
        }
        ctx.density[v] += n;
        left -= n;
    }
}

}  // namespace rivulet
