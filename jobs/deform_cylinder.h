#pragma once
// Per-group cylinder deformation (Hoetzlein & Höllerer 2009 §2.3): for each ring of the group's range, the
// spheres of its particles cut the ring's plane in circles; the ring's vertices go to centroid + r(theta_k)
// (cos, 0, sin) and the end rings' poles close the tube where the group's spheres end. Positions only;
// normals are their own job (cylinder_normals.h).
#include <cstdint>
#include <span>

#include "jobs/bin_sort.h"
#include "jobs/cross_section.h"
#include "jobs/cylinder_layout.h"
#include "jobs/particle_spans.h"

namespace rivulet {

inline constexpr std::uint32_t kMaxRingVertices = 256;  // U limit: ring scratch lives on the stack

struct DeformParams {
    BinGrid grid;
    CylinderLayout layout;
    CrossSectionParams section;
    AngleTable angles;  // U entries
};

// Rings of one group drawn over [vmin, vmax]: `ring[e]`, `particle[e]` are the entries of some of its
// rings, in ring order (a slice of its list, group_lists.h); every ring is independent, so a cylinder can
// be deformed in ring ranges. Circle scratch (cx, cz, rho) has one slot per entry. `vertices` is this
// cylinder's block, 6 floats per vertex.
void deform_cylinder(ConstPositions particles, std::span<const std::uint32_t> ring,
                     std::span<const std::uint32_t> particle, std::uint32_t vmin, std::uint32_t vmax,
                     const DeformParams& params, std::span<float> circle_cx, std::span<float> circle_cz,
                     std::span<float> circle_rho, std::span<float> vertices);

}  // namespace rivulet
