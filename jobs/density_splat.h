#pragma once
// Building the density volume (jobs/density_volume.h) from particles, as jobs of a frame: the particles'
// bounds give the grid (plan_density_grid); each particle is listed, by a counting sort, in every brick
// group of bricks whose samples it can reach (density_bin_count_chunk, chunk_major_prefix,
// density_bin_scatter_chunk); every brick a particle reaches gets an atlas slot in brick order
// (density_allocate_bricks); then each group sums its list into its samples and copies them to its stored
// bricks (density_splat_group). A group gathers rather than particles scattering, its list is in particle
// order, and every sample's sum is computed by the same formula from the same world-space coordinates, so
// the volume is the same bytes at any thread count, and the faces two bricks share get the same sums in
// both (across groups too).
#include <cstdint>
#include <span>
#include <string>

#include "jobs/density_volume.h"
#include "jobs/particle_spans.h"

namespace rivulet {

struct ParticleBounds {
    float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    bool finite = true;  // false when some coordinate is NaN or infinite
};
// Bounds of `p` (non-empty), and whether every coordinate is finite.
ParticleBounds particle_bounds(ConstPositions p);
// The union of two chunks' bounds.
ParticleBounds merge_bounds(const ParticleBounds& a, const ParticleBounds& b);

struct DensityGridParams {
    float h = 1;       // kernel support radius, world units
    float volume = 1;  // V_j
    float voxel = 0;   // world units; 0: h / 4, grown where the bounds need more than max_dim cells
    std::uint32_t max_dim = 128;  // cells per axis at most (a multiple of kBrickCells)
};

// The lattice covering `bounds` plus h on every side, its origin a whole number of voxels so a fixed voxel
// gives the same sample points in every frame. Throws std::invalid_argument when an explicit voxel would
// need more than max_dim cells on some axis (naming both) or when the bounds are not finite.
DensityGrid plan_density_grid(const ParticleBounds& bounds, const DensityGridParams& params);

// The brick whose cells hold (x, y, z), clamped into the grid.
std::uint32_t density_brick_of(const DensityGrid& grid, float x, float y, float z);

// Bricks one particle can reach at most (its entries in the bin sort).
std::uint32_t density_max_bricks_per_particle(const DensityGrid& grid);

// The bin sort lists particles per group of bricks rather than per brick: kGroupBricksX bricks along x
// by kGroupBricksY along y by kGroupBricksZ along z. A particle reaching several bricks of a group is
// listed and set up once, and the group sums its samples once (the faces its bricks share included), then
// copies them out to its stored bricks. Groups long in x keep a particle's rows of samples whole (a row
// cut by a group's face costs a vector in each group); groups four bricks across y list a particle in
// fewer groups (about 2.1 at a kernel of four voxels, 2.5 with 16 x 2 x 2); their samples stay in the core's
// second-level cache (180 KB).
inline constexpr std::uint32_t kGroupBricksX = 8, kGroupBricksY = 4, kGroupBricksZ = 2;
inline constexpr std::uint32_t kGroupEdgeX = kGroupBricksX * kBrickCells + 1;  // samples per group row
inline constexpr std::uint32_t kGroupEdgeY = kGroupBricksY * kBrickCells + 1;
inline constexpr std::uint32_t kGroupEdgeZ = kGroupBricksZ * kBrickCells + 1;
struct DensityGroups {
    std::uint32_t gx = 0, gy = 0, gz = 0;
    std::uint32_t count() const { return gx * gy * gz; }
};
DensityGroups density_groups(const DensityGrid& grid);

// Which bricks of its group something reaches: bit (c * kGroupBricksY + b) * kGroupBricksX + a for the
// group's local brick (a, b, c).
using GroupBrickMask = std::uint64_t;
static_assert(kGroupBricksX * kGroupBricksY * kGroupBricksZ <= 64, "a group's bricks must fit its mask");

// Pass 1 of the bin sort, per chunk: counts[g] += 1 for every group g one of the chunk's particles can
// reach (conservatively), and masks[g] |= the bricks of g it can reach. Both have
// density_groups(grid).count() entries, zeroed by the caller.
void density_bin_count_chunk(const DensityGrid& grid, ConstPositions p, std::span<std::uint32_t> counts,
                             std::span<GroupBrickMask> masks);
// Pass 2, per chunk: each particle's index (`first` + its index in `p`) at the cursor of every group it
// reaches (cursors from chunk_major_prefix), so a group lists its particles in particle order.
void density_bin_scatter_chunk(const DensityGrid& grid, ConstPositions p, std::uint32_t first,
                               std::span<std::uint32_t> cursors, std::span<std::uint32_t> entries);

// Serial: slot per brick (brick_slot, grid.bricks()) for every brick some particle reaches (its bit in
// `masks`, one per group), numbered in brick order, and slot_brick (slot -> brick; slots past its size
// are counted, not written); `groups_out` gets the groups with a stored brick, in order (it must hold
// density_groups(grid).count()), and `group_count` their number. Returns the number of bricks to store.
std::uint32_t density_allocate_bricks(const DensityGrid& grid, std::span<const GroupBrickMask> masks,
                                      std::span<std::int32_t> brick_slot, std::span<std::uint32_t> slot_brick,
                                      std::span<std::uint32_t> groups_out, std::uint32_t& group_count);

// One group: sums V_j W_poly6 of the particles of `p` it lists (entries [bin_start[group],
// bin_start[group + 1])), in order, into its samples, and writes every stored brick of it (brick_slot) to
// its atlas slot, with its least and greatest samples to slot_min / slot_max. V_j is grid.volume, or
// volumes.mass / volumes.density[j] where given (a density that is not positive and finite: grid.volume).
// Runs an AVX2 build where the CPU has it (jobs/cpu_dispatch.h; RIVULET_NO_AVX2=1 forces the baseline),
// the same bytes either way.
void density_splat_group(const DensityGrid& grid, std::uint32_t group, ConstPositions p,
                         const ParticleVolumes& volumes, std::span<const std::uint32_t> entries,
                         std::span<const std::uint32_t> bin_start, std::span<const std::int32_t> brick_slot,
                         std::span<float> atlas, std::span<float> slot_min, std::span<float> slot_max);

}  // namespace rivulet
