#pragma once
// The data the diffuse-object jobs share (Juckel & Beckhaus, "Rendering diffuse objects using particle
// systems inside voxelized surface geometry", §4.2-4.3): a voxel material (every attribute of a voxel but
// its colour), the grid's placement, and the particles' attributes as structure of arrays.
#include <cstdint>
#include <span>

#include "jobs/depth_key_map.h"
#include "jobs/diffuse_forces.h"
#include "jobs/vec3.h"

namespace rivulet {

struct VoxelMaterial {
    std::uint16_t max_density = 8;
    std::uint16_t emit_per_frame = 1;  // from fill_time and the scene's dt
    float alpha = 0.5f;
    float size = 0.03f;
    bool fade_color_set = false;  // else a particle fades to its own colour at the fade alpha
    std::uint32_t fade_rgba = 0;  // alpha always set
    float fade_size = 0.03f;
    float lifetime = 1;  // seconds of fading outside the active voxels
    float interpolation_time = 0.3f;
    float drag = 1;
    float jitter = 0.05f;
    bool color_set = false;  // the region's colour replaces the mesh's
    std::uint32_t rgba = 0;  // when color_set
    VoxelForce force;
    VoxelStep step;  // the force and drag over the scene's dt
    bool about_region = false;
    Vec3f region_centre;  // object space
};

inline constexpr std::uint16_t kNoMaterial = 0xffff;
inline constexpr std::uint32_t kOutsideVoxel = 0xffffffffu;

// Where the grid lies in object space; voxel (ix, iy, iz) is [origin + i * cell, origin + (i + 1) * cell).
struct DiffuseGrid {
    Vec3f origin;
    float cell = 1;
    int nx = 0, ny = 0, nz = 0;

    // The voxel holding object-space point p, or kOutsideVoxel.
    std::uint32_t voxel_of(Vec3f p) const {
        const float inv = 1 / cell;
        const float fx = (p.x - origin.x) * inv, fy = (p.y - origin.y) * inv, fz = (p.z - origin.z) * inv;
        if (!(fx >= 0 && fy >= 0 && fz >= 0 && fx < float(nx) && fy < float(ny) && fz < float(nz)))
            return kOutsideVoxel;
        const auto ix = static_cast<std::uint32_t>(fx), iy = static_cast<std::uint32_t>(fy),
                   iz = static_cast<std::uint32_t>(fz);
        return (iz * std::uint32_t(ny) + iy) * std::uint32_t(nx) + ix;
    }
    Vec3f voxel_min(std::uint32_t v) const {
        const std::uint32_t ix = v % std::uint32_t(nx), iy = v / std::uint32_t(nx) % std::uint32_t(ny),
                            iz = v / (std::uint32_t(nx) * std::uint32_t(ny));
        return origin + Vec3f{float(ix), float(iy), float(iz)} * cell;
    }
    Vec3f voxel_centre(std::uint32_t v) const { return voxel_min(v) + Vec3f{0.5f, 0.5f, 0.5f} * cell; }
};

// Wind behind a front: object-space points p with dot(p, direction) < front - band * jitter feel `wind`,
// and voxels there stop emitting. `jitter` in [0, 1) is each particle's (or voxel's) own, so the front is
// a ragged band rather than a clean cut. Off: front = -infinity.
struct DissolveFront {
    Vec3f direction{1, 0, 0};  // unit
    float front = -3.0e38f;
    float band = 0;
    Vec3f wind;
    bool active() const { return front > -3.0e38f; }
    bool behind(Vec3f p, float jitter) const { return dot(p, direction) < front - band * jitter; }
};

// One particle of a diffuse object as the sprite pass draws it: centre, world-space diameter, colour as
// RGBA8 (r in the low byte; alpha is the particle's opacity). The update writes one per particle, so the
// sort's staging gathers one record, not five arrays.
struct DiffuseSprite {
    float x = 0, y = 0, z = 0, size = 0;
    std::uint32_t rgba = 0;
};

// A particle's attributes beside its position, velocity and id (ParticleSet): the voxel it is in (or
// kOutsideVoxel: then it is fading, outside the active voxels), the colour and size it interpolates from
// and to over `duration`.
struct DiffuseAttributeSpans {
    std::span<std::uint32_t> voxel;
    std::span<std::uint32_t> from_rgba, to_rgba;
    std::span<float> from_size, to_size;
    std::span<float> elapsed, duration;
    std::span<DiffuseSprite> sprite;     // this frame's position, size and colour, for the sprite pass
    std::span<std::uint32_t> depth_key;  // the sprite's back-to-front sort key (DepthKeyMap)
};

// Per channel a + (b - a) t, t in [0, 1], in 8-bit fixed point (t to 1/256).
inline std::uint32_t lerp_rgba(std::uint32_t a, std::uint32_t b, float t) {
    const auto w = static_cast<std::int32_t>(t * 256.0f + 0.5f);
    std::uint32_t out = 0;
    for (int s = 0; s < 32; s += 8) {
        const auto ca = static_cast<std::int32_t>((a >> s) & 0xffu),
                   cb = static_cast<std::int32_t>((b >> s) & 0xffu);
        out |= static_cast<std::uint32_t>(ca + (((cb - ca) * w + 128) >> 8)) << s;
    }
    return out;
}

}  // namespace rivulet
