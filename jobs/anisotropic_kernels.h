#pragma once
// Anisotropic kernels for the marching-slices field (Yu & Turk 2013, "Reconstructing surfaces of
// particle-based fluids using anisotropic kernels", §4-5): each particle's kernel is an ellipsoid shaped
// by its neighbours, so a flat surface is made of kernels stretched along it (its bumps averaged away)
// and a thin sheet of kernels stretched along the sheet (it stays one sheet, not a string of beads).
//
// Per particle i, over its neighbours j within `radius` (itself included), with weights
// w = 1 - (|x_j - x_i| / radius)^3:
//   - the weighted mean m_i and covariance C_i of the neighbours' positions (the sums in float lanes over
//     the candidates in bucket order, the lanes added in double in a fixed order);
//   - the smoothed centre x_i + smoothing (m_i - x_i) (their eq. 6, lambda = `smoothing`): averages the
//     particles' jitter out of the centres, and pulls surface particles in towards their neighbours;
//   - C_i = R diag(lambda_k) R^T by Eigen's SelfAdjointEigenSolver; as in the paper the axes follow the
//     eigenvalues (variances, not their square roots), each clamped to at least the largest / max_stretch
//     (their k_r), then scaled so the shortest is 1: axes a_k in [1, max_stretch];
//   - fewer than `min_neighbours` neighbours (a droplet, a lone particle) or a degenerate C: a sphere.
// Where this departs from the paper (docs/marching_slices.md, "Anisotropic kernels"): the shortest axis
// is the isotropic R_c and the kernel's amplitude is 1 / (a_1 a_2 a_3), so every kernel keeps the
// isotropic kernel's integral; a dense flat layer then has the same mean field as with spheres, and the
// spacing field's calibration (surface one radius out) carries over. The paper's kernel also keeps
// its integral (det G) but shortens the normal axis, which pulls the surface in.
//
// The kernel of particle i at offset d = p - centre_i is amp_i * f(d^T M_i d), f the isotropic kernel
// of squared distance (jobs/slice_field.h), M_i = R diag(1 / a_k^2) R^T. For the lookup cache's columns
// it is stored as what a column (fixed dx, dy) needs: d^T M d = a(dx, dy) + c (z - z'(dx, dy))^2 with
//   a(dx, dy) = sxx dx^2 + 2 sxy dx dy + syy dy^2   (the Schur complement of M's zz entry: a column
//                                                    meets the ellipsoid where a < R_c^2),
//   z'(dx, dy) = z_i + gx dx + gy dy,  c = M_zz,     gx = -M_xz / M_zz, gy = -M_yz / M_zz.
// A sphere is sxx = syy = c = amp = 1, sxy = gx = gy = 0.
#include <cstddef>
#include <cstdint>
#include <span>

#include "jobs/cell_hash.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct AnisotropyParams {
    float radius = 1;       // neighbourhood radius
    float max_stretch = 3;  // longest / shortest axis, >= 1
    float smoothing = 0;    // lambda in [0, 1]
    std::uint32_t min_neighbours = 20;
};

// Per particle: the smoothed centre and the kernel's shape, as above (structure of arrays).
struct KernelShapes {
    std::span<float> x, y, z;
    std::span<float> sxx, sxy, syy, gx, gy, c, amp;
};
struct ConstKernelShapes {
    std::span<const float> sxx, sxy, syy, gx, gy, c, amp;
};

// Shapes of particles [begin, end) of `p`, hashed in `hash` with cells at least `params.radius` wide and
// the coordinates sorted into it (jobs/cell_hash.h, sort_cell_hash_positions). Reads only `p` and `hash`:
// chunks can run in parallel, and give the same bits in any order.
void anisotropic_kernels(ConstPositions p, const CellHash& hash, std::size_t begin, std::size_t end,
                         const AnisotropyParams& params, KernelShapes out);

}  // namespace rivulet
