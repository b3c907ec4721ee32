#pragma once
// Parameters of marching slices (Janisz §3.2) and how the particle radius maps onto the field
// F = sum of f(|s - p|) over particles within R_c, fluid where F >= iso (jobs/slice_field.h).
//
// The spacing field (default): R_c and iso follow the data's particle spacing d (`spacing`, or measured
//   by number density, jobs/particle_spacing.h, on the first frame of 1,024 particles or more, see
//   SlicesExtractor::field): spacing_field(d / radius) is the
//   one pair for which a lone particle is a sphere of `radius` and a flat layer of particles d apart
//   has its surface one radius outside its outer centres, so the surface sits where the particles'
//   spheres are, however densely they sample the fluid. R_c runs from 1.03 radii (d = r / 4) to 2.20
//   (d = 2 r).
// The classic field: R_c = rc_factor * radius (default 2) and iso = calibrated_iso(rc_factor) when
//   iso <= 0, the mean field one radius above a cubic lattice of spacing 2 * radius: right for data two
//   radii apart only (a lone particle gives a sphere of 1.158 radii; denser data push the surface out).
// voxel = radius / 2 when voxel <= 0.
#include <cstdint>
#include <string>

namespace rivulet {

enum class SliceField : std::uint8_t { kSpacing, kClassic };
const char* slice_field_name(SliceField field);  // "spacing", "classic"
bool parse_slice_field(const std::string& name, SliceField& out);

// R_c and iso of one frame's field.
struct SliceFieldValues {
    float rc = 0, iso = 0;
    float spacing = 0;  // the data spacing they were calibrated for (world units); 0 for the classic field
};

struct SlicesSettings {
    float radius = 0.02f;            // particle radius, world units
    float voxel = 0;                 // cube edge; <= 0: radius / 2
    std::uint32_t block_cubes = 40;  // n: a block is n^3 cubes
    SliceField field = SliceField::kSpacing;
    float spacing = 0;                         // spacing field: particle spacing; <= 0: measured
    float rc_factor = 2.0f;                    // classic field: R_c / radius
    float iso = 0;                             // classic field: threshold; <= 0: calibrated_iso(rc_factor)
    std::uint32_t max_blocks = 1u << 20;       // non-empty blocks a frame may have
    std::uint64_t max_triangles = 1ull << 26;  // triangles a frame may have
    std::uint32_t max_grid_cubes = 1u << 20;   // cubes along any axis
    // Anisotropic kernels (jobs/anisotropic_kernels.h, Yu & Turk 2013): the longest kernel axis over the
    // shortest, in [1, kMaxAnisotropy]; 0: spheres. The shapes come from neighbours within
    // kAnisotropyNeighbourhood particle spacings, centres are smoothed by anisotropy_smoothing.
    float anisotropy = 0;
    float anisotropy_smoothing = 0;  // lambda in [0, 1]
    // Seed from every z column too: finds empty cavities (bubbles enclosing no particle) that the
    // heuristic and the face scan can miss, at the cost of evaluating every corner (docs/marching_slices.md).
    bool exhaustive_seeds = false;

    float voxel_size() const { return voxel > 0 ? voxel : 0.5f * radius; }
    // The field for data `data_spacing` apart (world units; ignored by the classic field, and by the
    // spacing field when `spacing` is set).
    SliceFieldValues field_values(float data_spacing) const;
    // The most R_c any frame can get: the classic R_c, or the spacing field's at the widest spacing.
    float max_rc() const;
    // How far one particle's kernel can reach: R_c times the longest axis.
    float reach_factor() const { return anisotropy > 0 ? anisotropy : 1.0f; }
    // Empty when valid, else what is wrong.
    std::string validate() const;
};

// F one unit above the top layer of a semi-infinite cubic lattice of `spacing` (radius 1, R_c =
// rc_factor), averaged over 8 x 8 points of a lattice cell.
double lattice_mean_field(double rc_factor, double spacing);
// The classic field's iso: lattice_mean_field(rc_factor, 2).
double calibrated_iso(double rc_factor);
// The iso at which a lone particle's field, f alone, is a sphere of radius 1 (R_c = rc_factor).
double lone_particle_iso(double rc_factor);

// The spacing field's range of particle spacings, in radii: closer data are taken as 1/4 apart, sparser
// as 2 (beyond one diameter apart particles do not touch, and a flat lattice has no surface one radius
// above it that a lone particle's sphere would also keep).
inline constexpr double kMinFieldSpacing = 0.25, kMaxFieldSpacing = 2.0;
// Anisotropic kernels: the largest axis ratio, the neighbourhood radius in particle spacings (about 65
// neighbours inside a fluid, 33 under a flat surface) and the fewest neighbours that shape a kernel
// (fewer: a droplet or a lone particle, a sphere).
inline constexpr float kMaxAnisotropy = 4.0f, kDefaultAnisotropy = 3.0f;
inline constexpr float kAnisotropyNeighbourhood = 3.0f;
inline constexpr std::uint32_t kAnisotropyMinNeighbours = 20;

// The spacing field's rule for particles `spacing` radii apart (clamped to the range above): the one
// R_c (in radii) and iso for which a lone particle is a sphere of radius 1 and a flat cubic lattice of
// that spacing has its surface, on average, one radius above its top centres.
struct SpacingField {
    double spacing = 2;      // the clamped spacing, radii
    double rc_factor = 2.2;  // R_c / radius
    double iso = 0.157;
};
SpacingField spacing_field(double spacing);
// An R_c factor above the spacing field's root for every spacing up to `spacing` (its bisection's upper
// end, and the widest reach the field can need).
inline double spacing_field_rc_bound(double spacing) {
    return 1.5 + 0.5 * spacing;
}

}  // namespace rivulet
