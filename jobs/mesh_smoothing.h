#pragma once
// Taubin λ|μ smoothing of a triangle mesh (Taubin 1995, "A signal processing approach to fair surface
// design") with a volume correction per connected component, for `mesh --smooth N`: marching cubes over a
// particle field leaves an orange peel of voxel-sized bumps on what should be flat water. Each of the N
// iterations is a shrinking Laplacian step (λ = 0.5) and an inflating one (μ = -0.53), which damps the
// bumps and keeps the large shapes; then every component's vertices move along their normals by one
// common distance that restores its enclosed volume (smoothing a droplet still rounds it, it does not
// shrink it). A component the smoothing collapses (half its volume gone, or turned inside out: a droplet of
// a few triangles) keeps its unsmoothed vertices. Normals are recomputed, area-weighted. Topology never
// changes.
//
// With per-vertex weights (jobs/smoothing_weights.h, Löschner et al. 2023) each vertex's steps are
// scaled by its weight, so droplets and thin sheets, which few particles hold, keep their shape.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace rivulet {

// Vertex neighbours from the triangles, compressed rows: neighbours of v are
// neighbours[offsets[v] .. offsets[v + 1]), ascending, each once.
struct MeshAdjacency {
    std::vector<std::uint32_t> offsets, neighbours;
};
MeshAdjacency mesh_adjacency(std::span<const std::uint32_t> indices, std::size_t vertex_count);

// One Laplacian step on vertices [begin, end): out = p + factor w (mean of neighbours - p), positions at
// `stride` floats per vertex (the first three), others copied; w = weights[v], or 1 when `weights` is
// empty. A vertex without neighbours stays.
void laplacian_step(std::span<const float> in, std::span<float> out, std::size_t stride,
                    const MeshAdjacency& adjacency, float factor, std::size_t begin, std::size_t end,
                    std::span<const float> weights = {});

struct SmoothingReport {
    std::uint32_t components = 0;
    std::uint32_t kept = 0;  // components smoothing collapsed or turned inside out, left unsmoothed
    double volume_before = 0, volume_after = 0;  // signed, summed over components
};

// Smooths `vertices6` (position and normal per vertex) in place; `iterations` Taubin pairs, each vertex's
// steps scaled by weights[v] when `weights` is not empty. Serial.
SmoothingReport smooth_mesh(std::span<float> vertices6, std::span<const std::uint32_t> indices,
                            int iterations, std::span<const float> weights = {});

}  // namespace rivulet
