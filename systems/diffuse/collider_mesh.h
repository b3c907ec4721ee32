#pragma once
// A solid obstacle for diffuse particles, in its own local frame (the scene moves it by an offset per frame).
// Juckel & Beckhaus, "Rendering diffuse objects using particle systems inside voxelized surface geometry"
// (§5.2): voxels of a diffuse object that overlap a solid are switched off (overlaps_box), and the particles
// in the remaining voxels test their step, a segment, against the solid's triangles and bounce (collide).
//
// "Inside" always means inside the triangles: the sphere is an icosphere whose vertices lie on the true
// sphere, so its faces lie slightly inside it, and every query agrees on that polyhedron.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "jobs/vec3.h"
#include "systems/diffuse/colored_mesh.h"

namespace rivulet {

// A motion or velocity v meeting a surface of outward normal n: its component into the surface reversed
// and scaled by `restitution`, the tangential part kept; unchanged if it does not point into the surface.
inline Vec3f reflect_off_surface(Vec3f v, Vec3f n, float restitution) {
    const float vn = dot(v, n);
    return vn < 0 ? v - n * ((1 + restitution) * vn) : v;
}

class ColliderMesh {
  public:
    // Icosphere with 1280 triangles centred at the origin; throws std::invalid_argument unless radius > 0.
    static ColliderMesh sphere(float radius);
    // 12 triangles centred at the origin; throws std::invalid_argument unless every half extent is > 0.
    static ColliderMesh box(Vec3f half_extents);
    // Any closed mesh (not verified: an open one leaks). Throws std::invalid_argument when it has no
    // triangles, a non-finite position or an index out of range. Colours are ignored.
    static ColliderMesh from_mesh(const ColoredMesh& m);

    Vec3f bounds_min() const { return lo_; }
    Vec3f bounds_max() const { return hi_; }
    std::size_t triangle_count() const { return normals_.size(); }
    // How far outside the surface a stopped particle is left: a fixed fraction of the bounding-box diagonal,
    // well above the rounding of moving a point into and out of the collider's frame.
    float skin() const { return skin_; }
    // A ball (local coordinates) that a segment must enter to collide: every triangle inside it, with room
    // for the skin and for the padding and rounding of the collision walk.
    Vec3f reach_centre() const { return reach_centre_; }
    float reach_radius() const { return reach_radius_; }

    // Inside the closed triangle surface. Exact for points off the surface: crossings of a +x ray are
    // counted with exact orientation signs and a consistent tie-break, so rays through edges and vertices
    // count once.
    bool contains(Vec3f local) const;
    // Conservative: false only when the axis-aligned box [lo, hi] (local coordinates) surely does not touch
    // the solid.
    bool overlaps_box(Vec3f lo, Vec3f hi) const;
    // A particle moving from p0 to p1 (local) during a step. Each time the segment enters the surface, the
    // rest of the motion is reflected about the triangle's plane with the normal component scaled by
    // `restitution` (tangential kept); `velocity` is reflected the same way. Up to a few bounces; if still
    // crossing, it stops skin() outside the first hit. Returns whether it hit. A particle that starts
    // outside never ends inside; one that starts inside is left alone, so it can leave.
    // Thread-safe and allocation-free.
    bool collide(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const;

    // 9 floats per triangle, counter-clockwise seen from outside (for rendering and debugging).
    std::span<const float> triangle_vertices() const { return corners_; }

  private:
    struct Entry {
        Vec3f point, normal;
    };

    explicit ColliderMesh(std::vector<float> corners);
    Vec3f corner(std::size_t tri, int k) const {
        const float* c = &corners_[9 * tri + 3 * static_cast<std::size_t>(k)];
        return {c[0], c[1], c[2]};
    }
    int cell_of(float x, int axis) const;
    // Parity of +x ray crossings; with use_classes, stops at the first cell of known side.
    bool ray_parity(Vec3f p, bool use_classes) const;
    std::size_t cell_index(int ix, int iy, int iz) const {
        return (static_cast<std::size_t>(iz) * static_cast<std::size_t>(dims_[1]) +
                static_cast<std::size_t>(iy)) *
                   static_cast<std::size_t>(dims_[0]) +
               static_cast<std::size_t>(ix);
    }
    // The nearest place where p0 -> p1 enters the surface from outside.
    bool first_entry(Vec3f p0, Vec3f p1, Entry& hit) const;
    bool triangle_touches_box(std::size_t tri, Vec3f center, Vec3f half) const;

    std::vector<float> corners_;  // 9 floats per triangle
    std::vector<Vec3f> normals_;  // unit, outward
    std::vector<float> offsets_;  // dot(normal, corner): planes, for a cheap rejection
    Vec3f lo_, hi_;               // bounds of the triangles
    float skin_ = 0;
    Vec3f reach_centre_;
    float reach_radius_ = 0;
    // Uniform grid over the bounds: triangles binned by their (slightly widened) bounding boxes, as offsets
    // into cell_tris_ per cell (CSR).
    Vec3f grid_lo_, cell_size_, inv_cell_;
    int dims_[3] = {1, 1, 1};
    std::vector<std::uint32_t> cell_start_, cell_tris_;
    // Per cell: whether the surface passes through it (kMixed) or, for cells no triangle touches, which side
    // of it the whole cell lies on. Lets contains() stop at the first empty cell its ray reaches.
    enum CellClass : std::uint8_t { kOutside, kInside, kMixed };
    std::vector<CellClass> cell_class_;
};

}  // namespace rivulet
