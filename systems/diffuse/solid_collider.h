#pragma once
// A diffuse object's obstacle in its own local frame (the scene moves it by an offset per frame): an
// exact sphere or box, or a closed triangle mesh (ColliderMesh). Juckel & Beckhaus, "Rendering diffuse
// objects using particle systems inside voxelized surface geometry" (§5.2): the voxels it overlaps are
// switched off (overlaps_box) and the particles' steps that enter it bounce (collide).
//
// Spheres and boxes answer in closed form, a few dozen flops a query: while a ball sweeps through a
// million particles, thousands of steps a frame reach it, and a triangle walk per step (several per bounce)
// was half the frame. Both shapes are convex, so one reflection always ends outside.
#include <cstdint>
#include <memory>

#include "jobs/vec3.h"
#include "systems/diffuse/collider_mesh.h"
#include "systems/diffuse/colored_mesh.h"

namespace rivulet {

class SolidCollider {
  public:
    // Throws std::invalid_argument unless radius > 0 (finite).
    static SolidCollider sphere(float radius);
    // Centred at the origin; throws std::invalid_argument unless every half extent is > 0 (finite).
    static SolidCollider box(Vec3f half_extents);
    // Any closed mesh, as ColliderMesh::from_mesh (and its errors).
    static SolidCollider mesh(const ColoredMesh& m);

    Vec3f bounds_min() const { return lo_; }
    Vec3f bounds_max() const { return hi_; }
    // How far outside the surface a bounced particle is left: a fixed fraction of the bounds' diagonal.
    float skin() const { return skin_; }
    // A ball (local coordinates) that every colliding step enters.
    Vec3f reach_centre() const { return reach_centre_; }
    float reach_radius() const { return reach_radius_; }

    // Strictly inside (a point on the surface is outside).
    bool contains(Vec3f local) const;
    // Conservative: false only when the box [lo, hi] surely does not touch the solid.
    bool overlaps_box(Vec3f lo, Vec3f hi) const;
    // A particle moving from p0 to p1 (local) during a step: where the segment first enters the solid,
    // the rest of the motion is reflected about the surface's tangent plane with the normal component
    // scaled by `restitution` (tangential kept), and `velocity` the same way; the particle restarts a skin
    // off the surface. Returns whether it hit. A particle that starts outside never ends inside; one that
    // starts inside is left alone, so it can leave. Thread-safe and allocation-free.
    bool collide(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const;

    // The form DiffuseColliderStep calls: collide_step(this, ...).
    static bool collide_step(const void* solid, Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution);

  private:
    enum class Kind : std::uint8_t { kSphere, kBox, kMesh };
    SolidCollider() = default;
    void set_extent(Vec3f half, float farthest);
    bool collide_sphere(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const;
    bool collide_box(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const;

    Kind kind_ = Kind::kSphere;
    float radius_ = 0;  // sphere
    Vec3f half_;        // box
    std::unique_ptr<const ColliderMesh> mesh_;
    Vec3f lo_, hi_;
    float skin_ = 0;
    Vec3f reach_centre_;
    float reach_radius_ = 0;
};

}  // namespace rivulet
