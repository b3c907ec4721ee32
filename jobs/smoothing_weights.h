#pragma once
// Per-vertex smoothing weights from the particles (Löschner, Böttcher, Jeske & Bender 2023, "Weighted
// Laplacian smoothing for surface reconstruction of particle-based fluids"): a vertex over the bulk of
// the fluid is smoothed fully, one over a droplet, a thin sheet or a lone particle hardly at all, so the
// orange peel goes and the splashes keep their shape and volume.
//
//   1. per particle, its weighted neighbour count n_i = sum over j with |x_i - x_j| < R of
//      1 - |x_i - x_j|^2 / R^2 (itself included);
//   2. per vertex, n interpolated there (Shepard: the cubic-spline-weighted mean of the n_i within R;
//      0 where no particle is);
//   3. w = smoothstep(min(n / n_full, 1)), smoothstep(x) = 6x^5 - 15x^4 + 10x^3, n_full the count of a
//      particle inside a cubic lattice of the data's spacing (the paper's normalisation constant, here
//      derived from the spacing rather than set by hand).
// R is twice the particle spacing. Serial, in index order: the same bits every run.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "jobs/particle_spans.h"

namespace rivulet {

// n_full: the weighted neighbour count of a particle inside a cubic lattice, for support R = ratio x
// spacing.
double lattice_neighbour_count(double ratio);

// Weights for the vertices of `vertices6` (position and normal per vertex), from `particles` whose
// spacing is `spacing` (> 0); `weights` gets one per vertex.
void smoothing_weights(ConstPositions particles, float spacing, std::span<const float> vertices6,
                       std::vector<float>& weights);

}  // namespace rivulet
