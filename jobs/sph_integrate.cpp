#include "jobs/sph_integrate.h"

#include <cmath>

namespace rivulet {

namespace {

// Removes the velocity component along n (unit, pointing out of the obstacle) that approaches the
// surface moving at `wall` velocity.
void stop_into(Vec3f& v, Vec3f n, Vec3f wall) {
    const float vn = dot(v - wall, n);
    if (vn < 0.0f) v = v - n * vn;
}

void sphere_contact(Vec3f& p, Vec3f& v, const SphereObstacle& s, float margin) {
    const Vec3f d = p - s.center;
    const float reach = s.radius + margin;
    const float d2 = dot(d, d);
    if (d2 >= reach * reach) return;
    const float len = std::sqrt(d2);
    const Vec3f n = len > 0.0f ? d * (1.0f / len) : Vec3f{0, 1, 0};
    p = s.center + n * reach;
    stop_into(v, n, {});
}

void box_contact(Vec3f& p, Vec3f& v, const BoxObstacle& box, float margin) {
    const float lo[3] = {box.min.x - margin, box.min.y - margin, box.min.z - margin};
    const float hi[3] = {box.max.x + margin, box.max.y + margin, box.max.z + margin};
    float q[3] = {p.x, p.y, p.z};
    for (int a = 0; a < 3; ++a) {
        if (!(q[a] > lo[a] && q[a] < hi[a])) return;
    }
    // Leave through the nearest face; the first one on ties, so it is reproducible.
    int best = 0;
    float best_depth = q[0] - lo[0];
    for (int k = 1; k < 6; ++k) {
        const int a = k / 2;
        const float depth = (k % 2) ? hi[a] - q[a] : q[a] - lo[a];
        if (depth < best_depth) best = k, best_depth = depth;
    }
    const int axis = best / 2;
    const bool upper = best % 2;
    q[axis] = upper ? hi[axis] : lo[axis];
    float n[3] = {0, 0, 0};
    n[axis] = upper ? 1.0f : -1.0f;
    p = {q[0], q[1], q[2]};
    stop_into(v, {n[0], n[1], n[2]}, {});
}

// Keeps one coordinate inside [lo, hi]; the wall moves at w along this axis.
void tank_axis(float& q, float& vq, float lo, float hi, float w) {
    if (q < lo) {
        q = lo;
        if (vq < w) vq = w;
    } else if (q > hi) {
        q = hi;
        if (vq > w) vq = w;
    }
}

}  // namespace

float sph_integrate(const SphParticlesIn& in, const SphAccelIn& accel, std::size_t begin, std::size_t end,
                    float dt, const SphBoundary& b, const ParticleSpans& out) {
    const float m = b.margin;
    const Vec3f lo = b.tank_min + Vec3f{m, m, m};
    const Vec3f hi = b.tank_max - Vec3f{m, m, m};
    float max_v2 = 0.0f;
    const bool accelerate = !accel.ax.empty();
    for (std::size_t i = begin; i < end; ++i) {
        Vec3f v{in.vx[i], in.vy[i], in.vz[i]};
        if (accelerate) v = v + Vec3f{accel.ax[i], accel.ay[i], accel.az[i]} * dt;
        Vec3f p{in.x[i] + v.x * dt, in.y[i] + v.y * dt, in.z[i] + v.z * dt};
        for (const SphereObstacle& s : b.spheres) sphere_contact(p, v, s, m);
        for (const BoxObstacle& box : b.boxes) box_contact(p, v, box, m);
        tank_axis(p.x, v.x, lo.x, hi.x, b.tank_velocity.x);
        tank_axis(p.y, v.y, lo.y, hi.y, b.tank_velocity.y);
        tank_axis(p.z, v.z, lo.z, hi.z, b.tank_velocity.z);
        out.x[i] = p.x, out.y[i] = p.y, out.z[i] = p.z;
        out.vx[i] = v.x, out.vy[i] = v.y, out.vz[i] = v.z;
        out.id[i] = in.id[i];
        const float v2 = dot(v, v);
        if (v2 > max_v2) max_v2 = v2;
    }
    return max_v2;
}

}  // namespace rivulet
