#include "jobs/ballistic_step.h"

#include <algorithm>
#include <cmath>

namespace rivulet {

float SurfaceGrid::sample(float x, float z) const {
    const float fx = (x - x0) / dx;
    const float fz = (z - z0) / dz;
    // Truncation is floor here because covered points have fx, fz >= 0.
    const int ix = std::clamp(static_cast<int>(fx), 0, nx - 2);
    const int iz = std::clamp(static_cast<int>(fz), 0, nz - 2);
    const float tx = std::clamp(fx - static_cast<float>(ix), 0.0f, 1.0f);
    const float tz = std::clamp(fz - static_cast<float>(iz), 0.0f, 1.0f);
    const float* r0 = heights + static_cast<std::size_t>(iz) * static_cast<std::size_t>(nx) + ix;
    const float* r1 = r0 + nx;
    const float a = r0[0] + (r0[1] - r0[0]) * tx;
    const float b = r1[0] + (r1[1] - r1[0]) * tx;
    return a + (b - a) * tz;
}

namespace {

struct Body {
    Vec3f p, v;
};

// Puts the particle on the contact surface; only an approaching velocity bounces, so a particle already
// leaving is not slowed twice.
void respond(Body& b, Vec3f normal, Vec3f on_surface, float restitution, float keep_tangential) {
    b.p = on_surface;
    const float vn = dot(b.v, normal);
    if (vn >= 0) return;
    const Vec3f tangential = b.v - normal * vn;
    b.v = tangential * keep_tangential + normal * (-vn * restitution);
}

void collide_sphere(Body& b, const SphereObstacle& s, float r, float restitution, float keep) {
    const Vec3f d = b.p - s.center;
    const float reach = s.radius + r;
    const float d2 = dot(d, d);
    if (d2 >= reach * reach) return;
    const float len = std::sqrt(d2);
    const Vec3f n = len > 0 ? d * (1.0f / len) : Vec3f{0, 1, 0};
    respond(b, n, s.center + n * reach, restitution, keep);
}

void collide_box(Body& b, const BoxObstacle& box, float r, float restitution, float keep) {
    const float lo[3] = {box.min.x - r, box.min.y - r, box.min.z - r};
    const float hi[3] = {box.max.x + r, box.max.y + r, box.max.z + r};
    float p[3] = {b.p.x, b.p.y, b.p.z};
    for (int a = 0; a < 3; ++a) {
        if (!(p[a] > lo[a] && p[a] < hi[a])) return;
    }
    // Leave through the nearest face: the smallest push, and the first one on ties so it is reproducible.
    int best = 0;
    float best_depth = p[0] - lo[0];
    for (int k = 1; k < 6; ++k) {
        const int a = k / 2;
        const float depth = (k % 2) ? hi[a] - p[a] : p[a] - lo[a];
        if (depth < best_depth) best = k, best_depth = depth;
    }
    const int axis = best / 2;
    const bool upper = best % 2;
    p[axis] = upper ? hi[axis] : lo[axis];
    float n[3] = {0, 0, 0};
    n[axis] = upper ? 1.0f : -1.0f;
    respond(b, {n[0], n[1], n[2]}, {p[0], p[1], p[2]}, restitution, keep);
}

bool inside(Vec3f p, Vec3f lo, Vec3f hi) {
    return p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z;
}

}  // namespace

void ballistic_step(const ParticleSpans& ps, std::span<const std::uint32_t> birth, std::size_t begin,
                    std::size_t end, const BallisticParams& params, const BallisticOutputs& out) {
    const float h = params.dt / static_cast<float>(params.substeps);
    const Vec3f dv = params.gravity * h;
    const float e = params.restitution;
    const float keep = 1.0f - params.friction;
    const float r = params.radius;
    const float floor_y = params.ground_y + r;
    const float rest2 = params.rest_speed * params.rest_speed;
    const SurfaceGrid& surface = params.surface;

    for (std::size_t i = begin; i < end; ++i) {
        if (params.now - birth[i] >= params.max_age) {
            out.fate[i] = kRecycled;
            continue;
        }
        Body b{{ps.x[i], ps.y[i], ps.z[i]}, {ps.vx[i], ps.vy[i], ps.vz[i]}};
        std::uint8_t fate = kAlive;
        bool grounded = false;
        for (int s = 0; s < params.substeps; ++s) {
            b.v = b.v + dv;
            b.p = b.p + b.v * h;
            if (surface.covers(b.p.x, b.p.z) && b.p.y < surface.sample(b.p.x, b.p.z)) {
                out.hit_x[i] = b.p.x;
                out.hit_z[i] = b.p.z;
                out.hit_momentum[i] = std::max(0.0f, -b.v.y);
                fate = kAbsorbed;
                break;
            }
            for (const SphereObstacle& sphere : params.spheres) collide_sphere(b, sphere, r, e, keep);
            for (const BoxObstacle& box : params.boxes) collide_box(b, box, r, e, keep);
            grounded = b.p.y < floor_y;
            if (grounded) respond(b, {0, 1, 0}, {b.p.x, floor_y, b.p.z}, e, keep);
        }
        ps.x[i] = b.p.x, ps.y[i] = b.p.y, ps.z[i] = b.p.z;
        ps.vx[i] = b.v.x, ps.vy[i] = b.v.y, ps.vz[i] = b.v.z;
        if (fate == kAlive) {
            // The finiteness tests also catch NaN, which fails every comparison.
            const bool lost =
                !inside(b.p, params.bounds_min, params.bounds_max) || !std::isfinite(b.v.x + b.v.y + b.v.z);
            if (lost || (grounded && dot(b.v, b.v) < rest2)) fate = kRecycled;
        }
        out.fate[i] = fate;
    }
}

}  // namespace rivulet
