#pragma once
// SPH fluid (Müller, Charypar & Gross 2003; Inácio et al. 2010 §III) as explicit phases the frame graph
// schedules, with two pressure solvers (SphDesc::solver): DFSPH (Bender & Koschier 2015/2017), incompressible
// at large time steps, and WCSPH (Tait), weakly compressible.
//
// One frame:
//   begin_frame(ps, frame);                                     // serial
//   for (p = next_phase(); p != kPhaseCount; p = next_phase())  // next_phase: serial, between phases
//       phases()[p].parallel ? run_phase(p, c, ps) for every c in [0, chunks()), any order, any thread
//                            : run_phase(p, 0, ps)
//       (every chunk of phase p finishes before next_phase is asked again)
//   end_frame(ps);                                              // serial
// A WCSPH substep is substep, grid_count, grid_cursors, grid_offsets, grid_scatter, density, forces,
// integrate. A DFSPH substep is substep, the four grid phases, warm_start, neighbours, then the divergence
// solve's residual (divergence, or predict taking it; correct + divergence until small), predict, the density
// solve (density_error, then correct + density_error until small) and integrate: next_phase decides the
// iterations from the chunks' error sums, added in chunk order, and the substeps from frame time left.
//
// chunks() is fixed at construction (from max_particles), never from the thread count; every parallel
// phase writes only its chunk's slots and every sum runs in a fixed neighbour order, so the bytes after a
// frame are the same at any thread count and any chunk schedule. Each substep sorts the particles by grid
// cell (ids travel with them): the ParticleSet ends every substep reordered by cell. Density, pressure and
// accelerations are recomputed every substep. All buffers are allocated in the constructor.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "jobs/ballistic_step.h"
#include "jobs/dfsph_lists.h"
#include "jobs/dfsph_solve.h"
#include "jobs/sph_density.h"
#include "jobs/sph_forces.h"
#include "jobs/sph_grid.h"
#include "jobs/sph_integrate.h"
#include "systems/particles/aligned_array.h"
#include "systems/particles/particle_set.h"
#include "systems/sim/sph_desc.h"

namespace rivulet {

// Grid and time-stepping limits (docs/limits.md): the tank is at most this many kernel radii along an
// axis and in all, and a frame at most kMaxSphSubsteps substeps.
inline constexpr std::uint32_t kMaxGridCellsPerAxis = 4096;
inline constexpr std::uint64_t kMaxGridCells = std::uint64_t{1} << 28;
inline constexpr int kMaxSphSubsteps = 4096;

// The fastest the tank may move over a frame (scripted or from an input track): as far as the step's CFL
// number lets the fluid go in max_substeps substeps. Faster, each substep asks more than that of the walls,
// every solve runs to max_iterations, and a frame takes minutes: the dam break (limit 132 m/s) ran at 0.8
// frames/s pushed at 100 m/s and over a minute a frame at 150.
double sph_max_tank_speed(const SphDesc& desc);

// What is wrong with `desc` for a simulation of up to `max_particles` ("" when nothing): a value out of
// range (named by its scene-file key), a grid over its limits, an initial fluid that is empty or holds
// more than max_particles (counted, never walked), or buffers over kMaxSimulationBytes. Takes a few
// milliseconds at most, whatever the desc.
std::string sph_desc_problem(const SphDesc& desc, std::size_t max_particles);
// Bytes SphSimulation allocates for a grid of `cells` and `max_particles`.
std::uint64_t sph_buffer_bytes(std::uint64_t cells, std::size_t max_particles);

struct SphPhase {
    const char* name;
    bool parallel;
};

class SphSimulation {
  public:
    enum Phase : std::size_t {
        kSubstep = 0,   // serial: container pose and grid placement for this substep
        kGridCount,     // parallel: cell keys, per-chunk cell counts
        kGridCursors,   // parallel (over cell ranges): per-chunk cursors within each cell, cell totals
        kGridOffsets,   // serial: cell ranges (prefix sum of the totals)
        kGridScatter,   // parallel: particles copied to cell order
        kDensity,       // parallel: density and pressure
        kForces,        // parallel: accelerations
        kIntegrate,     // parallel: velocities, positions, boundaries; written back into the ParticleSet
        kWarmStart,     // DFSPH, parallel: both solves' warm-start stiffness, into the new order
        kNeighbours,    // DFSPH, parallel: neighbour lists, density ratio, factor, the divergence warm start
        kDivergence,    // DFSPH, parallel: divergence solve residual, where the prediction does not take it
        kPredict,       // DFSPH, parallel: gravity, viscosity, density warm start (+ divergence residual)
        kCorrect,       // DFSPH, parallel: velocity correction of either solve
        kDensityError,  // DFSPH, parallel: density solve residual
        kPhaseCount
    };

    // Allocates every buffer for up to max_particles; throws std::invalid_argument on a bad desc.
    // `chunks` is the number of pieces each parallel phase is cut into: 0 picks one per 512 particles
    // of max_particles (1 to 64: 45 chunks at 24k). It never depends on the thread count.
    SphSimulation(const SphDesc& desc, std::size_t max_particles, std::size_t chunks = 0);

    // Fills `ps` (resized; must have capacity for sph_seed_count(desc)) with the desc's initial fluid,
    // ids 0..n-1, and resets time and the container. Throws std::length_error beyond max_particles.
    void seed(ParticleSet& ps);

    // Serial: places the container for this frame; WCSPH picks the frame's substep count here (equal
    // substeps, CFL-limited, <= max), DFSPH each substep's length as it starts (same limits, <= max).
    void begin_frame(ParticleSet& ps, std::uint64_t frame);
    // Serial: the phase to run next, kPhaseCount when the frame's substeps are done.
    std::size_t next_phase();
    std::span<const SphPhase> phases() const { return kPhases; }
    std::size_t chunks() const { return chunks_; }
    void run_phase(std::size_t phase, std::size_t chunk, ParticleSet& ps);
    void end_frame(ParticleSet& ps);
    // Between begin_frame and end_frame: every phase of the frame, each chunk in turn, on this thread.
    void run_phases_serial(ParticleSet& ps);

    void step_serial(ParticleSet& ps, std::uint64_t frame);
    void step_parallel(ParticleSet& ps, std::uint64_t frame);  // chunks via tbb::parallel_for

    // The user's container displacement (added to the scripted motion), taken at the next begin_frame.
    void set_container_offset(Vec3f offset) { user_offset_ = offset; }
    // The container box now (after the last completed substep).
    BoxCollider tank() const;

    const SphDesc& desc() const { return desc_; }
    float particle_mass() const { return fluid_.mass; }
    float support() const { return fluid_.kernels.h; }
    const SphFluidParams& fluid() const { return fluid_; }
    int substeps() const { return substeps_; }  // the frame's, so far
    // DFSPH, over the last frame: solver iterations (velocity corrections) summed over its substeps, and
    // the largest average density error (fraction of rest density) a substep's pressure solve left.
    int divergence_iterations() const { return divergence_iterations_; }
    int density_iterations() const { return density_iterations_; }
    double density_error() const { return density_error_; }
    float substep_dt() const { return dt_sub_; }
    double time() const { return time_; }
    // Per particle index of the ParticleSet after a frame: density and pressure at the start of the
    // frame's last substep (the set is in that substep's sorted order).
    std::span<const float> density() const { return rho_.span(n_); }
    std::span<const float> pressure() const { return p_.span(n_); }

  private:
    static constexpr std::array<SphPhase, kPhaseCount> kPhases{{{"sph.substep", false},
                                                                {"sph.grid_count", true},
                                                                {"sph.grid_cursors", true},
                                                                {"sph.grid_offsets", false},
                                                                {"sph.grid_scatter", true},
                                                                {"sph.density", true},
                                                                {"sph.forces", true},
                                                                {"sph.integrate", true},
                                                                {"sph.warm_start", true},
                                                                {"sph.neighbours", true},
                                                                {"sph.divergence", true},
                                                                {"sph.predict", true},
                                                                {"sph.correct", true},
                                                                {"sph.density_error", true}}};
    enum class Solve { kDivergence, kDensity };

    std::size_t chunk_begin(std::size_t c) const { return c * n_ / chunks_; }
    Vec3f scripted_offset(double t) const;
    SphNeighbourhood neighbourhood() const;
    DfsphContext dfsph_context() const;
    bool solve_done(float max_error_percent);
    void start_dfsph_substep();

    SphDesc desc_;
    SphFluidParams fluid_;
    std::size_t max_particles_;
    std::size_t chunks_;
    std::size_t n_ = 0;
    SphGrid grid_;
    std::vector<SphereObstacle> spheres_;
    std::vector<BoxObstacle> boxes_;
    SphBoundary boundary_;
    SphWalls walls_;

    // Frame state.
    double time_ = 0;
    int substeps_ = 1;
    int substep_ = 0;
    float dt_sub_ = 0;
    double frame_left_ = 0;  // of the frame's dt, after the substep running
    float v2_start_ = 0;     // the largest |v|^2 at the frame's start
    float wall_speed_ = 0;   // the container's, over the frame
    std::size_t last_phase_ = kPhaseCount;
    Solve solve_ = Solve::kDivergence;
    int iterations_ = 0;
    float chebyshev_ = 1.0f;  // the next residual pass's weight (dfsph_chebyshev_weight)
    int divergence_iterations_ = 0, density_iterations_ = 0;
    // The divergence solve's first look is the prediction's pass where the last substep's solve was done
    // at its first look (then the look costs no pass of its own); else a residual pass, so that a solve
    // that goes on does not throw a prediction away at every look.
    bool look_in_prediction_ = true;
    bool divergence_done_ = false;
    double density_error_ = 0;
    Vec3f user_offset_;
    Vec3f offset_begin_, offset_end_, offset_now_;

    // Buffers.
    AlignedArray<std::uint32_t> keys_;                    // per particle (store order)
    AlignedArray<std::uint32_t> counts_, cursors_;        // chunks x cells, each chunk's used in key_ranges_
    std::vector<SphKeyRange> key_ranges_;                 // chunks
    AlignedArray<std::uint32_t> cell_start_;              // cells + 1
    AlignedArray<std::uint32_t> cell_total_;              // cells
    AlignedArray<float> sx_, sy_, sz_, svx_, svy_, svz_;  // sorted copies
    AlignedArray<std::uint32_t> sid_, skey_;
    AlignedArray<float> rho_, p_, ax_, ay_, az_;  // per sorted particle
    AlignedArray<float> chunk_a2_, chunk_v2_;     // per chunk maxima

    // DFSPH: the cubic kernel, its wall integral, rest volume, lists; per sorted particle density ratio,
    // factor, stiffness, wall gradient and support; v* lives in ax_, ay_, az_.
    SphCubicKernel cubic_{1.0f};
    DfsphWallTable wall_table_;
    float volume_ = 0;
    float full_neighbours_ = 0;
    std::vector<DfsphChunkLists> lists_;
    AlignedArray<std::uint32_t> pair_begin_, pair_end_;
    AlignedArray<float> ratio_, factor_, k_, wall_gx_, wall_gy_, wall_gz_, support_;
    // Warm start (Bender & Koschier 2017): each solve's stiffness summed over its corrections, by sorted
    // index, this substep's and the last one's (read through source_, the index before the sort).
    AlignedArray<float> k_div_sum_, k_den_sum_, k_div_last_, k_den_last_;
    // The density solve's stiffness of the substep before the last (k_den_before_, by the last substep's
    // sorted index; k_den_before_next_ by this one's): its warm start is the smaller of the two.
    AlignedArray<float> k_den_before_, k_den_before_next_;
    AlignedArray<std::uint32_t> source_;
    AlignedArray<float> v4_;       // the solve's velocities packed (DfsphVelocities::v4)
    AlignedArray<float> v4_next_;  // the prediction's, which reads v4_; the two swap after it
    AlignedArray<float> x4_;       // the sorted positions packed (DfsphParticleOut::x4)
    float dt_last_ = 0;            // the last substep's length (0: nothing to warm-start from)
    AlignedArray<double> chunk_error_;
};

}  // namespace rivulet
