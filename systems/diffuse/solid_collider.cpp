#include "systems/diffuse/solid_collider.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace rivulet {
namespace {

// As ColliderMesh's stand-off: a fraction of the bounds' diagonal, far above float rounding at the scales
// a scene moves colliders by, far below anything visible.
constexpr float kSkinFraction = 1e-4f;

float comp(Vec3f v, int axis) {
    return axis == 0 ? v.x : axis == 1 ? v.y : v.z;
}

void set_comp(Vec3f& v, int axis, float x) {
    (axis == 0 ? v.x : axis == 1 ? v.y : v.z) = x;
}

}  // namespace

SolidCollider SolidCollider::sphere(float radius) {
    if (!(radius > 0) || !std::isfinite(radius))
        throw std::invalid_argument("SolidCollider::sphere: radius must be > 0");
    SolidCollider s;
    s.kind_ = Kind::kSphere;
    s.radius_ = radius;
    s.set_extent({radius, radius, radius}, radius);
    return s;
}

SolidCollider SolidCollider::box(Vec3f half_extents) {
    const Vec3f h = half_extents;
    if (!(h.x > 0 && h.y > 0 && h.z > 0) || !finite(h))
        throw std::invalid_argument("SolidCollider::box: half extents must be > 0");
    SolidCollider s;
    s.kind_ = Kind::kBox;
    s.half_ = h;
    s.set_extent(h, length(h));
    return s;
}

SolidCollider SolidCollider::mesh(const ColoredMesh& m) {
    SolidCollider s;
    s.kind_ = Kind::kMesh;
    s.mesh_ = std::make_unique<const ColliderMesh>(ColliderMesh::from_mesh(m));
    s.lo_ = s.mesh_->bounds_min();
    s.hi_ = s.mesh_->bounds_max();
    s.skin_ = s.mesh_->skin();
    s.reach_centre_ = s.mesh_->reach_centre();
    s.reach_radius_ = s.mesh_->reach_radius();
    return s;
}

// A shape centred at the origin: its bounds, its skin, and a reach ball with room beyond the farthest
// surface point for the skin and for rounding.
void SolidCollider::set_extent(Vec3f half, float farthest) {
    hi_ = half;
    lo_ = Vec3f{} - half;
    skin_ = kSkinFraction * length(hi_ - lo_);
    reach_centre_ = {};
    reach_radius_ = farthest * 1.001f + 2 * skin_;
}

bool SolidCollider::contains(Vec3f p) const {
    switch (kind_) {
        case Kind::kSphere:
            return dot(p, p) < radius_ * radius_;
        case Kind::kBox:
            return std::abs(p.x) < half_.x && std::abs(p.y) < half_.y && std::abs(p.z) < half_.z;
        case Kind::kMesh:
            break;
    }
    return mesh_->contains(p);
}

bool SolidCollider::overlaps_box(Vec3f lo, Vec3f hi) const {
    if (kind_ == Kind::kMesh) return mesh_->overlaps_box(lo, hi);
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return false;  // empty (or NaN)
    // Widened a little so that rounding errs towards "touches".
    const float widen = 0.1f * skin_;
    if (kind_ == Kind::kBox)
        return lo.x <= half_.x + widen && hi.x >= -half_.x - widen && lo.y <= half_.y + widen &&
               hi.y >= -half_.y - widen && lo.z <= half_.z + widen && hi.z >= -half_.z - widen;
    // The box's point nearest the centre.
    const Vec3f q{std::clamp(0.0f, lo.x, hi.x), std::clamp(0.0f, lo.y, hi.y), std::clamp(0.0f, lo.z, hi.z)};
    const float r = radius_ + widen;
    return dot(q, q) <= r * r;
}

bool SolidCollider::collide(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const {
    switch (kind_) {
        case Kind::kSphere:
            return collide_sphere(p0, p1, velocity, restitution);
        case Kind::kBox:
            return collide_box(p0, p1, velocity, restitution);
        case Kind::kMesh:
            break;
    }
    return mesh_->collide(p0, p1, velocity, restitution);
}

bool SolidCollider::collide_step(const void* solid, Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) {
    return static_cast<const SolidCollider*>(solid)->collide(p0, p1, velocity, restitution);
}

bool SolidCollider::collide_sphere(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const {
    const float r2 = radius_ * radius_;
    const float c = dot(p0, p0) - r2;
    if (!(c >= 0)) return false;  // starts inside (or is not a number): left alone
    const Vec3f d = p1 - p0;
    const float a = dot(d, d), b = dot(p0, d);
    // |p0 + t d|^2 = r^2 at t = (-b -+ sqrt(b^2 - a c)) / a; the entry is the smaller root, written as
    // c / (-b + sqrt(...)) so that a step starting near the surface does not lose it to cancellation.
    float t = 2;
    if (b < 0 && a > 0) {
        const float disc = b * b - a * c;
        if (disc > 0) t = c / (-b + std::sqrt(disc));
    }
    if (!(t <= 1)) {
        // No entry within the step, unless rounding put the root a hair past its end.
        if (!(dot(p1, p1) < r2)) return false;
        p1 = p0;
        return true;
    }
    const Vec3f n = normalize(p0 + d * t);
    const Vec3f hit = n * radius_;
    const float e = restitution > 0 ? restitution : 0;
    const Vec3f stop = hit + n * skin_;
    // Moving off a sphere's point without a component into it never comes closer than that point.
    Vec3f end = stop + reflect_off_surface(p1 - hit, n, e);
    if (dot(end, end) < r2) end = stop;  // rounding only
    p1 = end;
    velocity = reflect_off_surface(velocity, n, e);
    return true;
}

bool SolidCollider::collide_box(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const {
    if (contains(p0)) return false;
    const Vec3f d = p1 - p0;
    // Slabs: the segment is inside the box between the last entry and the first exit over the axes.
    float t_in = -std::numeric_limits<float>::infinity(), t_out = std::numeric_limits<float>::infinity();
    int axis = -1;
    float side = 0;
    for (int k = 0; k < 3; ++k) {
        const float o = comp(p0, k), dk = comp(d, k), h = comp(half_, k);
        if (dk == 0) {
            if (!(std::abs(o) < h)) t_out = -std::numeric_limits<float>::infinity();  // along, outside it
            continue;
        }
        const float ta = (-h - o) / dk, tb = (h - o) / dk;
        const float near = std::min(ta, tb), far = std::max(ta, tb);
        if (near > t_in) t_in = near, axis = k, side = dk > 0 ? -1.0f : 1.0f;
        t_out = std::min(t_out, far);
    }
    if (!(axis >= 0 && t_in < t_out && t_in >= 0 && t_in <= 1)) {
        if (!contains(p1)) return false;
        p1 = p0;  // rounding only
        return true;
    }
    Vec3f hit = p0 + d * t_in;
    set_comp(hit, axis, side * comp(half_, axis));
    Vec3f n{};
    set_comp(n, axis, side);
    const float e = restitution > 0 ? restitution : 0;
    // The box lies behind the face's plane; a motion without a component into it stays in front.
    const Vec3f stop = hit + n * skin_;
    Vec3f end = stop + reflect_off_surface(p1 - hit, n, e);
    if (contains(end)) end = stop;  // rounding only
    p1 = end;
    velocity = reflect_off_surface(velocity, n, e);
    return true;
}

}  // namespace rivulet
