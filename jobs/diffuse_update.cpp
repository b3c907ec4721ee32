#include "jobs/diffuse_update.h"

#include <algorithm>
#include <cstring>

#include "jobs/counter_rng.h"
#include "jobs/cpu_dispatch.h"
#include "jobs/vector_lanes.h"

namespace rivulet {
namespace {

constexpr int kCollisionRounds = 3;

// The step p0 -> p against one collider, in the collider's frame, so a moving collider pushes the
// particles it sweeps over.
RIVULET_INLINE bool collide_one(const DiffuseColliderStep& c, float dt, float restitution, Vec3f p0, Vec3f& p,
                                Vec3f& v) {
    const Vec3f lo{std::min(p0.x, p.x), std::min(p0.y, p.y), std::min(p0.z, p.z)};
    const Vec3f hi{std::max(p0.x, p.x), std::max(p0.y, p.y), std::max(p0.z, p.z)};
    if (hi.x < c.swept_min.x || hi.y < c.swept_min.y || hi.z < c.swept_min.z || lo.x > c.swept_max.x ||
        lo.y > c.swept_max.y || lo.z > c.swept_max.z)
        return false;
    const Vec3f cv = (c.offset1 - c.offset0) * (1 / dt);
    Vec3f local1 = p - c.offset1, rel = v - cv;
    if (!c.collide(c.solid, p0 - c.offset0, local1, rel, restitution)) return false;
    p = local1 + c.offset1;
    v = rel + cv;
    return true;
}

// A moving solid may push a particle into another one, so with several solids the tests repeat while
// they bounce; still solids come last in each round and so always have the final word. One solid's
// answer is final: it never leaves a particle inside itself.
// Opaque to the caller (jobs/cpu_dispatch.h): the AVX2 lanes clear the registers' upper halves before it,
// as its baseline code and the solids' tests behind the function pointers need.
RIVULET_OPAQUE void collide_all(const DiffuseUpdateContext& ctx, Vec3f p0, Vec3f& p, Vec3f& v) {
    const int rounds = ctx.colliders.size() > 1 ? kCollisionRounds : 1;
    for (int round = 0; round < rounds; ++round) {
        bool hit = false;
        for (int still = 0; still < 2; ++still)
            for (const DiffuseColliderStep& c : ctx.colliders)
                if ((c.offset0 == c.offset1) == (still == 1))
                    hit |= collide_one(c, ctx.dt, ctx.restitution, p0, p, v);
        if (!hit) break;
    }
}

// Particle i moved from old_voxel to voxel (kOutsideVoxel: no active voxel) with `elapsed` on its clock
// before this step: the attributes it now interpolates towards, then this step of its interpolation as
// update_lanes makes it lane by lane (its sprite's size and colour, its clock); the move is listed for
// the density. Returns whether it has faded out.
RIVULET_INLINE bool change_voxel_body(const DiffuseUpdateContext& ctx, std::size_t i, std::uint32_t old_voxel,
                                      std::uint32_t voxel, float elapsed, std::uint32_t* move) {
    move[0] = old_voxel, move[1] = voxel;
    const DiffuseAttributeSpans& A = ctx.attributes;
    std::uint32_t from_rgba = A.from_rgba[i], to_rgba = A.to_rgba[i];
    float from_size = A.from_size[i], to_size = A.to_size[i], duration = A.duration[i];
    bool fading = old_voxel == kOutsideVoxel;
    const float t0 = duration > 0 ? std::min(1.0f, elapsed / duration) : 1.0f;
    const std::uint32_t now_rgba = lerp_rgba(from_rgba, to_rgba, t0);
    const float now_size = from_size + (to_size - from_size) * t0;
    if (voxel != kOutsideVoxel) {
        // Entering a voxel (re-entering included: the fade stops, life goes on).
        const VoxelMaterial& m = ctx.materials[ctx.material[voxel]];
        from_rgba = now_rgba, to_rgba = ctx.voxel_rgba[voxel];
        from_size = now_size, to_size = m.size;
        elapsed = 0, duration = m.interpolation_time, fading = false;
    } else if (!fading) {
        // Leaving the active voxels: fade by the last voxel's fading attributes (§4.3).
        const std::uint16_t mi = old_voxel != kOutsideVoxel ? ctx.material[old_voxel] : kNoMaterial;
        const VoxelMaterial& m = ctx.materials[mi == kNoMaterial ? 0 : mi];
        from_rgba = now_rgba;
        to_rgba = m.fade_color_set ? m.fade_rgba : (now_rgba & 0x00ffffffu) | (m.fade_rgba & 0xff000000u);
        from_size = now_size, to_size = m.fade_size;
        elapsed = 0, duration = m.lifetime, fading = true;
    }
    A.voxel[i] = voxel;
    A.from_rgba[i] = from_rgba, A.to_rgba[i] = to_rgba;
    A.from_size[i] = from_size, A.to_size[i] = to_size, A.duration[i] = duration;
    const bool moving = fading || elapsed < duration;
    const float later = elapsed + ctx.dt;
    const float q = later / duration;
    const float t = duration > 0 ? (q < 1.0f ? q : 1.0f) : 1.0f;
    const float now = moving ? later : elapsed;
    A.sprite[i].size = moving ? from_size + (to_size - from_size) * t : to_size;
    A.sprite[i].rgba = moving ? lerp_rgba(from_rgba, to_rgba, t) : to_rgba;
    A.elapsed[i] = now;
    return fading && now >= duration;
}

// The voxel change in a build of each lane width's instruction set. Called from the AVX2 lanes, a baseline
// (SSE) build runs while the caller's vectors are live in the registers' upper halves (the compiler sees
// which registers it uses and keeps them there), and on Intel every one of its instructions then pays
// for the mixed state: the whole update took 2.4 times as long.
[[gnu::noinline]] RIVULET_AVX2 bool change_voxel_avx2(const DiffuseUpdateContext& ctx, std::size_t i,
                                                      std::uint32_t old_voxel, std::uint32_t voxel,
                                                      float elapsed, std::uint32_t* move) {
    return change_voxel_body(ctx, i, old_voxel, voxel, elapsed, move);
}
[[gnu::noinline]] bool change_voxel_baseline(const DiffuseUpdateContext& ctx, std::size_t i,
                                             std::uint32_t old_voxel, std::uint32_t voxel, float elapsed,
                                             std::uint32_t* move) {
    return change_voxel_body(ctx, i, old_voxel, voxel, elapsed, move);
}

// What a block lists as it goes: its dead, ascending, and its particles' voxel changes.
struct BlockLists {
    std::uint32_t* dead;
    std::uint32_t dead_n;
    std::uint32_t* moves;
    std::uint32_t move_n;
    const std::uint32_t *born, *born_end;  // the block's births not yet reached, ascending
};

// L particles as vectors: F floats, I signed and U unsigned 32-bit lanes.
template <int L>
struct Lanes {
    using F = typename VectorLanes<L>::f;
    using I = typename VectorLanes<L>::i;
    using U = typename VectorLanes<L>::u;
    using F4 = typename VectorLanes<4>::f;

    // The first n lanes from memory (the rest zero); n = L reads one vector.
    template <class V, class T>
    RIVULET_INLINE static void load(V& v, const T* p, int n) {
        v = V{};
        if (n == L)
            std::memcpy(&v, p, sizeof v);
        else
            std::memcpy(&v, p, std::size_t(n) * sizeof(T));
    }
    template <class V, class T>
    RIVULET_INLINE static void store(T* p, const V& v, int n) {
        if (n == L)
            std::memcpy(p, &v, sizeof v);
        else
            std::memcpy(p, &v, std::size_t(n) * sizeof(T));
    }
    // L whole sprites: x, y, z, size of four lanes transposed into four 16-byte stores, then the colours.
    RIVULET_INLINE static void store_sprites(DiffuseSprite* out, const F& x, const F& y, const F& z,
                                             const F& size, const U& rgba) {
        for (int h = 0; h < L; h += 4) {
            F4 x4, y4, z4, s4;
            for (int l = 0; l < 4; ++l)
                x4[l] = x[h + l], y4[l] = y[h + l], z4[l] = z[h + l], s4[l] = size[h + l];
            const F4 t0 = __builtin_shufflevector(x4, y4, 0, 4, 1, 5),
                     t1 = __builtin_shufflevector(x4, y4, 2, 6, 3, 7);
            const F4 t2 = __builtin_shufflevector(z4, s4, 0, 4, 1, 5),
                     t3 = __builtin_shufflevector(z4, s4, 2, 6, 3, 7);
            const F4 rows[4] = {
                __builtin_shufflevector(t0, t2, 0, 1, 4, 5), __builtin_shufflevector(t0, t2, 2, 3, 6, 7),
                __builtin_shufflevector(t1, t3, 0, 1, 4, 5), __builtin_shufflevector(t1, t3, 2, 3, 6, 7)};
            for (int l = 0; l < 4; ++l) {
                std::memcpy(static_cast<void*>(&out[h + l]), &rows[l], sizeof(F4));
                out[h + l].rgba = rgba[h + l];
            }
        }
    }
    // Per lane the step-table column of voxel v: its material while active, else `outside`
    // (kOutsideVoxel included). One table read a lane and no branch (lanes mix inside and outside
    // particles at random): a voxel past the grid (which has at least one) reads the last one's entry
    // and is then replaced.
    // Built from scalars in registers: lane stores read back as a vector would wait for each store.
    RIVULET_INLINE static void step_columns(U& columns, std::span<const std::uint16_t> column, const U& v,
                                            std::uint32_t outside) {
        const U last = U{} + static_cast<std::uint32_t>(column.size() - 1);
        const U at = v < last ? v : last;
        std::uint32_t c[L];
        for (int l = 0; l < L; ++l) c[l] = column[at[l]];
        U out;
        if constexpr (L == 8)
            out = U{c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]};
        else
            out = U{c[0], c[1], c[2], c[3]};
        columns = v <= last ? out : U{} + outside;
    }
    // Bit l set where lane l of the comparison result is true.
    RIVULET_INLINE static unsigned bits(const I& m) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
        // One vmovmskps: only the AVX2 build runs eight lanes, and GCC checks a builtin's instruction set
        // where it is expanded, in update_range_avx2 (Clang merges the two halves itself).
        if constexpr (L == 8) return unsigned(__builtin_ia32_movmskps256(__builtin_bit_cast(F, m)));
#endif
        return lane_bits(m);
    }
};

// One row of the step table at each lane's column. Eight lanes and eight columns: one permute where the
// compiler has a variable shuffle (GCC); a lookup per lane otherwise.
template <int L>
RIVULET_INLINE void pick(typename Lanes<L>::F& out, const float* row, const typename Lanes<L>::I& column,
                         bool eight_columns) {
#if defined(__GNUC__) && !defined(__clang__)
    if constexpr (L == 8) {
        if (eight_columns) {
            typename Lanes<L>::F table;
            std::memcpy(&table, row, sizeof table);
            out = __builtin_shuffle(table, column);
            return;
        }
    }
#endif
    (void)eight_columns;
    for (int l = 0; l < L; ++l) out[l] = row[column[l]];
}

// Particles [i, i + n), n <= L: motion (apply_voxel_step, lane by lane the same operations), collisions,
// voxel lookup, voxel changes, interpolation and the sprite.
// `ctx` is the caller's copy (update_range), `shared` the context itself, for the calls out of line.
template <int L>
RIVULET_INLINE void update_lanes(const DiffuseUpdateContext& ctx, const DiffuseUpdateContext& shared,
                                 std::size_t i, int n, BlockLists& lists) {
    using Ln = Lanes<L>;
    using F = typename Ln::F;
    using I = typename Ln::I;
    using U = typename Ln::U;
    const ParticleSpans& P = ctx.particles;
    const DiffuseAttributeSpans& A = ctx.attributes;
    const std::size_t columns = diffuse_step_columns(ctx.materials.size());
    const bool eight = columns == 8;

    F px0, py0, pz0, vx, vy, vz;
    U old_voxel;
    Ln::load(px0, &P.x[i], n), Ln::load(py0, &P.y[i], n), Ln::load(pz0, &P.z[i], n);
    Ln::load(vx, &P.vx[i], n), Ln::load(vy, &P.vy[i], n), Ln::load(vz, &P.vz[i], n);
    Ln::load(old_voxel, &A.voxel[i], n);

    // The step each lane takes: its voxel's material while that voxel is active, else the outside's.
    const auto outside = static_cast<std::uint32_t>(ctx.materials.size());
    U old_column;
    Ln::step_columns(old_column, ctx.column, old_voxel, outside);
    const I column = I(old_column);

    F ax = (F{} + ctx.accel.x), ay = (F{} + ctx.accel.y), az = (F{} + ctx.accel.z);
    if (ctx.dissolve.active()) {
        // Each particle its own place in the front's band and its own gust, so the shape breaks up
        // rather than sliding away whole.
        for (int l = 0; l < n; ++l) {
            const std::uint64_t h = mix64(P.id[i + std::size_t(l)]);
            const float ragged = float(h >> 40) * (1.0f / 16777216.0f);
            const float gust = 0.3f + 1.4f * float((h >> 16) & 0xffffffu) * (1.0f / 16777216.0f);
            if (ctx.dissolve.behind(Vec3f{px0[l], py0[l], pz0[l]} - ctx.offset, ragged)) {
                const Vec3f a = ctx.accel + ctx.dissolve.wind * gust;
                ax[l] = a.x, ay[l] = a.y, az[l] = a.z;
            }
        }
    }
    const F zero = (F{} + 0.0f);
    const auto get = [&](F& out, int r) {
        pick<L>(out, ctx.steps.data() + std::size_t(r) * columns, column, eight);
    };
    F flag, fx, fy, fz;
    get(flag, kStepLinear);
    const I linear = flag > zero;
    get(flag, kStepOrbit);
    const I orbit = flag > zero;
    get(flag, kStepTurn);
    const I turn = flag > zero;
    get(fx, kStepVectorX), get(fy, kStepVectorY), get(fz, kStepVectorZ);
    ax = (linear ? ax + fx : ax), ay = (linear ? ay + fy : ay), az = (linear ? az + fz : az);

    // The centre of the centred forces: the region's, or the particle's voxel's.
    F cx = zero, cy = zero, cz = zero;
    get(flag, kStepCentred);
    const I centred = flag > zero;
    if (Ln::bits(centred)) {
        get(flag, kStepAboutRegion);
        const I about = flag > zero;
        get(cx, kStepCentreX), get(cy, kStepCentreY), get(cz, kStepCentreZ);
        cx += ctx.offset.x, cy += ctx.offset.y, cz += ctx.offset.z;
        for (unsigned b = Ln::bits(centred & ~about); b; b &= b - 1) {
            const int l = __builtin_ctz(b);
            const Vec3f c = ctx.grid.voxel_centre(old_voxel[l]) + ctx.offset;
            cx[l] = c.x, cy[l] = c.y, cz[l] = c.z;
        }
    }

    // Constant acceleration integrated exactly, or the orbit's rotation in phase space.
    F dt, half_dt2;
    get(dt, kStepDt), get(half_dt2, kStepHalfDt2);
    F px = px0 + vx * dt + ax * half_dt2, py = py0 + vy * dt + ay * half_dt2,
      pz = pz0 + vz * dt + az * half_dt2;
    F nvx = vx + ax * dt, nvy = vy + ay * dt, nvz = vz + az * dt;
    F cosv, sinv;
    get(cosv, kStepCos), get(sinv, kStepSin);
    if (Ln::bits(orbit)) {
        F inv_w2, sin_over_w, w_sin;
        get(inv_w2, kStepInvW2), get(sin_over_w, kStepSinOverW), get(w_sin, kStepWSin);
        const F sx = cx + ax * inv_w2, sy = cy + ay * inv_w2, sz = cz + az * inv_w2;
        const F dx = px0 - sx, dy = py0 - sy, dz = pz0 - sz;
        px = (orbit ? sx + dx * cosv + vx * sin_over_w : px);
        py = (orbit ? sy + dy * cosv + vy * sin_over_w : py);
        pz = (orbit ? sz + dz * cosv + vz * sin_over_w : pz);
        nvx = (orbit ? vx * cosv - dx * w_sin : nvx);
        nvy = (orbit ? vy * cosv - dy * w_sin : nvy);
        nvz = (orbit ? vz * cosv - dz * w_sin : nvz);
    }
    F drag;
    get(drag, kStepDrag);
    vx = nvx * drag, vy = nvy * drag, vz = nvz * drag;
    if (Ln::bits(turn)) {
        // A velocity field that turns about the axis: the particle is carried along it exactly.
        F one_minus_cos, decay, shift;
        get(one_minus_cos, kStepOneMinusCos), get(decay, kStepDecay), get(shift, kStepShift);
        const F dx = px - cx, dy = py - cy, dz = pz - cz;
        const F along = dx * fx + dy * fy + dz * fz;
        const F ex = dx - fx * along, ey = dy - fy * along, ez = dz - fz * along;
        const F kx = fy * ez - fz * ey, ky = fz * ex - fx * ez, kz = fx * ey - fy * ex;
        const F proj = (fx * ex + fy * ey + fz * ez) * one_minus_cos;
        const F tx = (ex * cosv + kx * sinv + fx * proj) * decay,
                ty = (ey * cosv + ky * sinv + fy * proj) * decay,
                tz = (ez * cosv + kz * sinv + fz * proj) * decay;
        const F s = along + shift;
        px = (turn ? cx + fx * s + tx : px);
        py = (turn ? cy + fy * s + ty : py);
        pz = (turn ? cz + fz * s + tz : pz);
    }

    // Colliders: the lanes whose step's box meets a collider's swept box take the scalar tests.
    unsigned near = 0;
    for (const DiffuseColliderStep& c : ctx.colliders) {
        const I apart = ((px0 > (F{} + c.swept_max.x)) & (px > (F{} + c.swept_max.x))) |
                        ((px0 < (F{} + c.swept_min.x)) & (px < (F{} + c.swept_min.x))) |
                        ((py0 > (F{} + c.swept_max.y)) & (py > (F{} + c.swept_max.y))) |
                        ((py0 < (F{} + c.swept_min.y)) & (py < (F{} + c.swept_min.y))) |
                        ((pz0 > (F{} + c.swept_max.z)) & (pz > (F{} + c.swept_max.z))) |
                        ((pz0 < (F{} + c.swept_min.z)) & (pz < (F{} + c.swept_min.z)));
        if (!Ln::bits(~apart)) continue;
        // The step in the collider's frame, as collide_one moves it, against the reach ball.
        const F sx = px0 - c.offset0.x, sy = py0 - c.offset0.y, sz = pz0 - c.offset0.z;
        const F dx = (px - c.offset1.x) - sx, dy = (py - c.offset1.y) - sy, dz = (pz - c.offset1.z) - sz;
        const F wx = c.reach_centre.x - sx, wy = c.reach_centre.y - sy, wz = c.reach_centre.z - sz;
        const F len2 = dx * dx + dy * dy + dz * dz, along = wx * dx + wy * dy + wz * dz;
        const F t = len2 > zero ? along / len2 : zero;
        const F u = t > zero ? (t < F{} + 1.0f ? t : F{} + 1.0f) : zero;
        const F qx = wx - dx * u, qy = wy - dy * u, qz = wz - dz * u;
        const I passes_by = (qx * qx + qy * qy + qz * qz) > (F{} + c.reach_radius * c.reach_radius);
        near |= Ln::bits(~(apart | passes_by));
    }
    for (unsigned b = near & ((1u << n) - 1u); b; b &= b - 1) {
        const int l = __builtin_ctz(b);
        Vec3f p{px[l], py[l], pz[l]}, v{vx[l], vy[l], vz[l]};
        collide_all(shared, Vec3f{px0[l], py0[l], pz0[l]}, p, v);
        px[l] = p.x, py[l] = p.y, pz[l] = p.z, vx[l] = v.x, vy[l] = v.y, vz[l] = v.z;
    }
    Ln::store(&P.x[i], px, n), Ln::store(&P.y[i], py, n), Ln::store(&P.z[i], pz, n);
    Ln::store(&P.vx[i], vx, n), Ln::store(&P.vy[i], vy, n), Ln::store(&P.vz[i], vz, n);

    // The voxel each lane is in now (DiffuseGrid::voxel_of, lane by lane).
    const DiffuseGrid& g = ctx.grid;
    const float inv = 1 / g.cell;
    const F gx = ((px - ctx.offset.x) - g.origin.x) * inv, gy = ((py - ctx.offset.y) - g.origin.y) * inv,
            gz = ((pz - ctx.offset.z) - g.origin.z) * inv;
    const I inside = (gx >= zero) & (gy >= zero) & (gz >= zero) & (gx < (F{} + float(g.nx))) &
                     (gy < (F{} + float(g.ny))) & (gz < (F{} + float(g.nz)));
    const U cell_index =
        (U(__builtin_convertvector(gz, I)) * std::uint32_t(g.ny) + U(__builtin_convertvector(gy, I))) *
            std::uint32_t(g.nx) +
        U(__builtin_convertvector(gx, I));
    const U in_grid = inside ? cell_index : U{} + kOutsideVoxel;
    U new_column;
    Ln::step_columns(new_column, ctx.column, in_grid, outside);
    const U voxel = new_column == outside ? U{} + kOutsideVoxel : in_grid;
    const unsigned changed = Ln::bits(voxel != old_voxel) & ((1u << n) - 1u);

    // Interpolation towards the voxel's colour and size; a settled particle (done, not fading) keeps its
    // own, and its clock need not run. The lanes that changed voxel are redone one by one below, after
    // their new targets are written: writing those first would make these vector loads wait for the
    // lanes' scalar stores.
    const I fading = old_voxel == (U{} + kOutsideVoxel);
    F elapsed, duration, from_size, to_size;
    U from_rgba, to_rgba;
    Ln::load(elapsed, &A.elapsed[i], n), Ln::load(duration, &A.duration[i], n);
    Ln::load(from_size, &A.from_size[i], n), Ln::load(to_size, &A.to_size[i], n);
    Ln::load(from_rgba, &A.from_rgba[i], n), Ln::load(to_rgba, &A.to_rgba[i], n);
    // The births among the lanes (DiffuseUpdateContext::born) get their state here, in registers, stored
    // once for the lanes: a store per field and birth before these loads would make them wait.
    unsigned born = 0;
    for (; lists.born != lists.born_end && *lists.born < i + std::size_t(n); ++lists.born)
        born |= 1u << (*lists.born - i);
    for (unsigned b = born; b; b &= b - 1) {
        const int l = __builtin_ctz(b);
        const std::uint32_t v = old_voxel[l];
        const VoxelMaterial& m = ctx.materials[ctx.material[v]];
        to_rgba[l] = ctx.voxel_rgba[v], from_rgba[l] = ctx.voxel_rgba[v] & 0x00ffffffu;
        from_size[l] = to_size[l] = m.size;
        elapsed[l] = 0, duration[l] = m.interpolation_time;
    }
    if (born) {
        Ln::store(&A.from_rgba[i], from_rgba, n), Ln::store(&A.to_rgba[i], to_rgba, n);
        Ln::store(&A.from_size[i], from_size, n), Ln::store(&A.to_size[i], to_size, n);
        Ln::store(&A.duration[i], duration, n);
    }
    const I moving = fading | (elapsed < duration);
    const F later = elapsed + ctx.dt;
    const F q = later / duration;
    const F one = (F{} + 1.0f);
    const F t = duration > zero ? (q < one ? q : one) : one;
    const F size = (moving ? from_size + (to_size - from_size) * t : to_size);
    const I w = __builtin_convertvector(t * 256.0f + 0.5f, I);
    U rgba = U{};
    for (int s = 0; s < 32; s += 8) {
        const I ca = I((from_rgba >> s) & 0xffu), cb = I((to_rgba >> s) & 0xffu);
        rgba |= U(ca + (((cb - ca) * w + 128) >> 8)) << s;
    }
    rgba = moving ? rgba : to_rgba;
    const F now = (moving ? later : elapsed);
    Ln::store(&A.elapsed[i], now, n);
    if (n == L)
        Ln::store_sprites(&A.sprite[i], px, py, pz, size, rgba);
    else
        for (int l = 0; l < n; ++l) A.sprite[i + std::size_t(l)] = {px[l], py[l], pz[l], size[l], rgba[l]};
    // The sort key (DepthKeyMap::key, lane by lane the same operations).
    const DepthKeyMap& dm = ctx.depth_map;
    const F depth = ((px - dm.origin.x) * dm.direction.x + (py - dm.origin.y) * dm.direction.y) +
                    (pz - dm.origin.z) * dm.direction.z;
    const F scaled = (depth - dm.depth_min) * dm.scale();
    const F key_max = F{} + float(kDepthKeyMax);
    const F clamped = scaled > zero ? (scaled < key_max ? scaled : key_max) : zero;
    const U key = U{} + kDepthKeyMax - U(__builtin_convertvector(clamped, I));
    Ln::store(&A.depth_key[i], key, n);
    unsigned dead = Ln::bits(fading & (now >= duration)) & ~changed;
    for (unsigned b = changed; b; b &= b - 1) {
        const int l = __builtin_ctz(b);
        const std::size_t k = i + std::size_t(l);
        std::uint32_t* move = lists.moves + 2 * lists.move_n++;
        // A voxel of the same material and colour gives the particle the targets it has: it keeps its
        // interpolation (a particle fading in still takes the voxel's interpolation time, where starting
        // over on every crossing would never let a jittering one arrive), and only the move is listed.
        if (voxel[l] != kOutsideVoxel && new_column[l] == old_column[l] && !fading[l] &&
            ctx.voxel_rgba[voxel[l]] == to_rgba[l]) {
            move[0] = old_voxel[l], move[1] = voxel[l];
            A.voxel[k] = voxel[l];
            continue;
        }
        bool faded;
        if constexpr (L == 8)
            faded = change_voxel_avx2(shared, k, old_voxel[l], voxel[l], elapsed[l], move);
        else
            faded = change_voxel_baseline(shared, k, old_voxel[l], voxel[l], elapsed[l], move);
        dead |= unsigned(faded) << l;
    }
    // The frame's sprites are the particles as this step leaves them, the dead among them transparent:
    // their places go to births or to copies after the sprites are sorted.
    for (unsigned b = dead & ((1u << n) - 1u); b; b &= b - 1) {
        const std::size_t k = i + std::size_t(__builtin_ctz(b));
        A.sprite[k].rgba &= 0x00ffffffu;
        lists.dead[lists.dead_n++] = static_cast<std::uint32_t>(k);
    }
}

template <int L>
RIVULET_INLINE void update_range(const DiffuseUpdateContext& ctx, std::size_t begin, std::size_t end,
                                 BlockLists& out) {
    // A copy whose address never escapes, so its counts stay in registers: through `out` every store
    // to the lists might change them, and the compiler would read them again after each.
    BlockLists lists = out;
    // The same for the context: the lanes read a copy the functions out of line never see, so its
    // fields (the scene's constants, the arrays' places) can be held across the loop instead of read
    // again after every store.
    const DiffuseUpdateContext local = ctx;
    std::size_t i = begin;
    for (; i + L <= end; i += L) update_lanes<L>(local, ctx, i, L, lists);
    if (i < end) update_lanes<L>(local, ctx, i, int(end - i), lists);
    out = lists;
}

RIVULET_AVX2 void update_range_avx2(const DiffuseUpdateContext& ctx, std::size_t begin, std::size_t end,
                                    BlockLists& lists) {
    update_range<8>(ctx, begin, end, lists);
}

}  // namespace

void diffuse_update_block(std::size_t block, const DiffuseUpdateContext& ctx) {
    const std::size_t begin = block * ctx.block_size;
    const std::size_t end = std::min(ctx.particles.size(), begin + ctx.block_size);
    const std::uint32_t* born = std::lower_bound(ctx.born.data(), ctx.born.data() + ctx.born.size(),
                                                 static_cast<std::uint32_t>(begin));
    const std::uint32_t* born_end =
        std::lower_bound(born, ctx.born.data() + ctx.born.size(), static_cast<std::uint32_t>(end));
    BlockLists lists{ctx.dead.data() + block * ctx.block_size,
                     0,
                     ctx.moves.data() + 2 * block * ctx.block_size,
                     0,
                     born,
                     born_end};
    if (cpu_has_avx2())
        update_range_avx2(ctx, begin, end, lists);
    else
        update_range<4>(ctx, begin, end, lists);
    ctx.dead_count[block] = lists.dead_n;
    ctx.move_count[block] = lists.move_n;
}

void diffuse_apply_moves(const DiffuseUpdateContext& ctx, std::size_t blocks) {
    std::uint32_t* density = ctx.density.data();
    for (std::size_t b = 0; b < blocks; ++b) {
        const std::uint32_t* m = ctx.moves.data() + 2 * b * ctx.block_size;
        for (std::uint32_t k = 0; k < ctx.move_count[b]; ++k) {
            if (m[2 * k] != kOutsideVoxel) --density[m[2 * k]];
            if (m[2 * k + 1] != kOutsideVoxel) ++density[m[2 * k + 1]];
        }
    }
}

}  // namespace rivulet
