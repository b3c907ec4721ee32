#pragma once
// The density volume of Inácio, Nobrega, Carvalho & von Wangenheim ("Interactive Simulation and
// Visualization of Fluids with Surface Raycasting", eq. 3):
//
//   F(r) = sum_j V_j W_poly6(r - r_j),   W_poly6(r) = 315 / (64 pi h^9) (h^2 - |r|^2)^3 for |r| < h,
//
// sampled at the points of a lattice of spacing `voxel` and stored sparsely in bricks of 8^3 cells. A
// brick holds 9^3 samples: the corners of its cells, the far faces shared with the next bricks, so any
// point inside it interpolates from that brick alone. Bricks that no particle reaches are not stored
// (F = 0 there). Stored bricks live in an atlas of kAtlasBricks x kAtlasBricks x layers bricks laid out
// as one linear 3D array of samples (x fastest), so the renderer uploads the used layers in one call.
#include <cstdint>
#include <span>

namespace rivulet {

inline constexpr std::uint32_t kBrickCells = 8;               // cells per brick edge
inline constexpr std::uint32_t kBrickEdge = kBrickCells + 1;  // samples per brick edge
inline constexpr std::uint32_t kBrickSamples = kBrickEdge * kBrickEdge * kBrickEdge;
inline constexpr std::uint32_t kAtlasBricks = 32;                       // atlas width and height, in bricks
inline constexpr std::uint32_t kAtlasEdge = kAtlasBricks * kBrickEdge;  // atlas width and height, samples
inline constexpr std::uint32_t kAtlasLayerBricks = kAtlasBricks * kAtlasBricks;

// The sample lattice: sample (i, j, k) lies at (ox + voxel i, oy + voxel j, oz + voxel k), for i in
// [0, samples_x()) and so on; brick (a, b, c) holds samples [8a, 8a + 8] x [8b, 8b + 8] x [8c, 8c + 8].
struct DensityGrid {
    float ox = 0, oy = 0, oz = 0;
    float voxel = 1;
    std::uint32_t bx = 0, by = 0, bz = 0;  // bricks per axis
    float h = 1;                           // kernel support radius
    float volume = 1;                      // V_j (every particle the same)

    std::uint32_t bricks() const { return bx * by * bz; }
    std::uint32_t samples_x() const { return bx * kBrickCells + 1; }
    std::uint32_t samples_y() const { return by * kBrickCells + 1; }
    std::uint32_t samples_z() const { return bz * kBrickCells + 1; }
    std::uint32_t brick_index(std::uint32_t a, std::uint32_t b, std::uint32_t c) const {
        return (c * by + b) * bx + a;
    }
    float x(std::uint32_t i) const { return ox + voxel * static_cast<float>(i); }
    float y(std::uint32_t j) const { return oy + voxel * static_cast<float>(j); }
    float z(std::uint32_t k) const { return oz + voxel * static_cast<float>(k); }
};

// Offset of sample (i, j, k) of a brick (each in [0, 9)) stored in atlas slot `slot`.
inline std::size_t atlas_offset(std::uint32_t slot, std::uint32_t i, std::uint32_t j, std::uint32_t k) {
    const std::uint32_t sx = slot % kAtlasBricks, sy = (slot / kAtlasBricks) % kAtlasBricks;
    const std::uint32_t sz = slot / kAtlasLayerBricks;
    const std::size_t x = sx * kBrickEdge + i, y = sy * kBrickEdge + j, z = std::size_t(sz) * kBrickEdge + k;
    return (z * kAtlasEdge + y) * kAtlasEdge + x;
}
// Atlas layers (of kAtlasLayerBricks bricks, kBrickEdge samples deep) that `slots` bricks occupy.
inline std::uint32_t atlas_layers(std::uint32_t slots) {
    return (slots + kAtlasLayerBricks - 1) / kAtlasLayerBricks;
}
// Samples of an atlas with `layers` layers.
inline std::size_t atlas_samples(std::uint32_t layers) {
    return std::size_t(layers) * kBrickEdge * kAtlasEdge * kAtlasEdge;
}

// A frame's volume, read-only (the slot or the offline mesher owns the memory).
struct DensityVolumeView {
    DensityGrid grid;
    float iso = 0.5f;                           // the surface is F = iso
    std::span<const std::int32_t> brick_slot;   // per brick (grid.brick_index): atlas slot, or -1 (F = 0)
    std::span<const std::uint32_t> slot_brick;  // per stored brick, in slot order: its brick index
    std::span<const float> slot_min, slot_max;  // per stored brick: the least and greatest of its samples
    std::span<const float> atlas;               // atlas_samples(atlas_layers(stored())) floats
    std::uint32_t stored() const { return static_cast<std::uint32_t>(slot_min.size()); }

    // F at lattice point (i, j, k) (0 outside the lattice and in bricks not stored). On a brick border the
    // lower brick's copy is read; both copies are the same value.
    float sample(std::uint32_t i, std::uint32_t j, std::uint32_t k) const {
        if (i >= grid.samples_x() || j >= grid.samples_y() || k >= grid.samples_z()) return 0.0f;
        const auto brick = [](std::uint32_t s, std::uint32_t n) {
            return s / kBrickCells < n ? s / kBrickCells : n - 1;
        };
        const std::uint32_t a = brick(i, grid.bx), b = brick(j, grid.by), c = brick(k, grid.bz);
        const std::int32_t slot = brick_slot[grid.brick_index(a, b, c)];
        if (slot < 0) return 0.0f;
        return atlas[atlas_offset(static_cast<std::uint32_t>(slot), i - a * kBrickCells, j - b * kBrickCells,
                                  k - c * kBrickCells)];
    }
};

}  // namespace rivulet
