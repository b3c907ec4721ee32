#pragma once
// The iterations of divergence-free SPH (Bender & Koschier 2015, 2017) over the lists of
// jobs/dfsph_lists.h, in velocity form. Each solve is a relaxed Jacobi iteration on a stiffness k_i >= 0
// per particle (the paper's kappa_i times dt), with the velocities always those the stiffness applied
// so far gives:
//   residual: the density's rate of change  rate_i = sum_j V grad W_ij . (v_i - v_j) + the walls' term
//             -> the signed residual r_i, per second, of
//                divergence solve: rate_i (0 for particles with under min_support, whose deficient
//                                  density would read as expansion)
//                density solve:    ((rho_i / rho0 - 1) c + dt rate_i) / dt, c = catch_up <= 1: the
//                                  error the step starts with is removed over dt / c, not one step
//                                  (at small steps, removing it at once turns any mismatch between
//                                  predicted and realized density into a large velocity)
//             -> the new total max(k_total_i + omega r_i alpha_i, 0), of which the change is written
//                to k_i; the error summed is max(r_i, 0) dt, a fraction of rest density
//   correct:  v_i -= sum_j (k_i + k_j) V grad W_ij + k_i grad B_i
// The total may shrink (an overshoot is taken back), which the per-iteration clamp of the 2015 paper
// cannot do; omega = 1/2 damps Jacobi's checkerboard modes (as SPlisHSPlasH's solver does).
// Chebyshev's semi-iterative method (Golub & Varga 1961; Wang 2015 applies it to position-based
// dynamics) accelerates the iteration: from the second iteration on, the new total is extrapolated from
// the one an iteration back, max(before + w (jacobi - before), 0), with the weights w of
// dfsph_chebyshev_weight; the change last applied is still in k, so before = k_total - k. Relaxed Jacobi
// alone removes about a third of the error an iteration at one spacing a substep; with the weights the
// solves take about half the iterations (docs/sph.md). The
// divergence solve's residual can be taken by the prediction's pass (dfsph_predict), which reads the same
// pairs and velocities: warm-started, that solve is done at its first look on most substeps, and the
// look then costs no pass of its own. Each pass writes only particles [begin, end) and reads neighbours
// in list order: the bytes do not depend on the split. Residual passes return their chunk's summed error
// (double) for the solver's average. Where the CPU has AVX2 the passes run a VEX-encoded build of the
// same operations (jobs/cpu_dispatch.h): the same bytes.
#include <cmath>
#include <cstddef>
#include <span>

#include "jobs/dfsph_lists.h"

namespace rivulet {

// A solve's velocities, as columns and again as four floats a particle (x, y, z, +0): a residual pass
// reads a neighbour's velocity as one load from the latter. Passes that write velocities write both.
struct DfsphVelocities {
    std::span<float> vx, vy, vz;
    std::span<float> v4;
};

// What every pass reads: sorted positions, the lists, the walls' gradients and velocity.
struct DfsphContext {
    std::span<const float> x, y, z;
    std::span<const float> x4;               // the same positions packed (x, y, z, 0) by the list build
    std::span<const DfsphChunkLists> lists;  // per chunk
    std::span<const std::uint32_t> pair_begin, pair_end;
    std::span<const float> wall_gx, wall_gy, wall_gz, support;
    float wall_velocity[3] = {0, 0, 0};
    // Divergence solve: particles with less support (DfsphParticleOut::support) are left alone.
    float min_support = 0;
};

// A solve's warm start: the last substep's summed stiffness times `share` (the carried fraction times
// the ratio of the steps). A particle the solves leave alone shrinks by the share every substep and
// would reach subnormal floats after a few hundred, where every product of the passes costs tens of
// cycles on x86 (they made a dam break's early and late frames 20 % slower in all); below
// kDfsphWarmFloor, twenty orders under any stiffness that moves a particle, it is zero instead.
inline constexpr float kDfsphWarmFloor = 1e-30f;
inline float dfsph_warm_stiffness(float share, float last) {
    const float k = share * last;
    return std::abs(k) >= kDfsphWarmFloor ? k : 0.0f;
}

inline constexpr float kDfsphRelaxation = 0.5f;

// The weights apply to a solve's first iterations only (the 24k dam break's solves take at most about
// 15); past them plain relaxed Jacobi goes on. The clamp at zero makes a solve nonlinear, and a few
// solves of the 256k dam break, extrapolated to the iteration limit, stalled at 0.19 % average error
// where plain Jacobi reached 0.118 %.
inline constexpr int kDfsphChebyshevIterations = 30;

// The Chebyshev weight of the residual pass after `iterations` corrections, from the last weight and
// rho, an estimate of the relaxed Jacobi iteration's spectral radius in [0, 1): 1 (plain Jacobi) before
// the first correction, past kDfsphChebyshevIterations and where rho is 0, else w_1 = 2 / (2 - rho^2),
// w_m = 4 / (4 - rho^2 w_{m-1}).
inline float dfsph_chebyshev_weight(float rho, int iterations, float last) {
    if (rho <= 0.0f || iterations <= 0 || iterations > kDfsphChebyshevIterations) return 1.0f;
    const float rho2 = rho * rho;
    return iterations == 1 ? 2.0f / (2.0f - rho2) : 4.0f / (4.0f - rho2 * last);
}

// What the divergence solve's residual reads and writes besides the velocities: the factor and the
// stiffness summed so far (k_total) in, the change out (k).
struct DfsphDivergenceCheck {
    std::span<const float> factor, k_total;
    std::span<float> k;
};

// The divergence solve's residual pass, where dfsph_predict does not take it; `chebyshev` the weight of
// dfsph_chebyshev_weight (1: plain relaxed Jacobi, which does not read k).
double dfsph_divergence_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                                 float dt, std::span<const float> v4, const DfsphDivergenceCheck& check,
                                 float chebyshev = 1.0f);

// The density solve's residual pass; `chebyshev` as above.
double dfsph_residual(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end, float dt,
                      std::span<const float> v4, std::span<const float> density_ratio,
                      std::span<const float> factor, std::span<const float> k_total, std::span<float> k,
                      float catch_up = 1.0f, float chebyshev = 1.0f);

void dfsph_correct(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                   std::span<const float> k, const DfsphVelocities& v);

struct DfsphPredictSums {
    float max_v2 = 0;               // the chunk's largest |v_i + dt a_i|^2
    double divergence_error = 0.0;  // the chunk's summed divergence error, as a residual pass's
};

// One pass over the pairs with the velocities v4 (packed: x, y, z, 0 a particle) that does two things:
// - the divergence solve's residual (`check`), the rate summed per pair as V grad W_ij . (v_i - v_j);
// - the prediction, valid once that solve is done: non-pressure forces, explicit, gravity and viscosity
//   (the SPH discretisation of nu lap v of Monaghan, a_i = 10 nu sum_j V (v_ij . x_ij) / (|x_ij|^2 +
//   0.01 h^2) grad W_ij), and the density solve's warm start (the correction of dfsph_correct with
//   stiffness k_warm, the same bytes as a correction pass after it). Writes v*_i = v_i + dt a_i -
//   correction_i to `out`, whose v4 must be another buffer (neighbours read v).
// Where the divergence solve goes on, its correction follows and this pass again: the prediction made
// here is then thrown away.
DfsphPredictSums dfsph_predict(const DfsphContext& c, std::size_t chunk, std::size_t begin, std::size_t end,
                               float dt, float nu, float h, const float gravity[3], std::span<const float> v4,
                               std::span<const float> k_warm, const DfsphDivergenceCheck& check,
                               const DfsphVelocities& out);

}  // namespace rivulet
