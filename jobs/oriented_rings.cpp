#include "jobs/oriented_rings.h"

#include <immintrin.h>
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>

#include "jobs/deform_cylinder.h"

namespace rivulet {
namespace {

using Vec = Eigen::Vector3f;

Vec position(ConstPositions p, std::uint32_t i) {
    return {p.x[i], p.y[i], p.z[i]};
}

// The polyline the rings follow, with cumulative arc length.
struct Path {
    const RingScratch& s;
    std::uint32_t points = 0;
    std::uint32_t first_level_point = 0;  // the point of level 0 (1 when the path was extended back)

    Vec at(std::uint32_t i) const { return {s.path_x[i], s.path_y[i], s.path_z[i]}; }
    void set(std::uint32_t i, const Vec& v) { s.path_x[i] = v.x(), s.path_y[i] = v.y(), s.path_z[i] = v.z(); }
    float length() const { return s.arc[points - 1]; }
    void measure() {
        s.arc[0] = 0;
        for (std::uint32_t i = 1; i < points; ++i) s.arc[i] = s.arc[i - 1] + (at(i) - at(i - 1)).norm();
    }
    // The point at arc length t and its fractional point index; `from` is a segment at or before t's
    // (the rings ask in order of t, so each keeps a cursor and the walk along the path stays linear).
    Vec point(float t, float& index, std::uint32_t& from) const {
        std::uint32_t& i = from;
        while (i + 2 < points && s.arc[i + 1] <= t) ++i;
        const float seg = s.arc[i + 1] - s.arc[i];
        const float f = seg > 0 ? std::clamp((t - s.arc[i]) / seg, 0.0f, 1.0f) : 0.0f;
        index = static_cast<float>(i) + f;
        return at(i) + f * (at(i + 1) - at(i));
    }
};

// A unit vector normal to t, from the world axis t leans on least.
Vec any_normal(const Vec& t) {
    Eigen::Index axis = 0;
    t.cwiseAbs().minCoeff(&axis);
    const Vec a = Vec::Unit(axis);
    return (a - a.dot(t) * t).normalized();
}

// The level centroids as the path (`p`: the members' positions, in their order) (a single level: its
// principal axis, Eigen's eigen-solver on the covariance), smoothed, then extended to the end particles'
// centres along the end directions.
Path build_path(ConstPositions p, std::span<const std::uint32_t> members,
                std::span<const std::uint32_t> level, std::uint32_t first_level, std::uint32_t levels,
                const RingScratch& s) {
    Path path{s};
    std::uint32_t m = 0, filled = 0;
    for (std::uint32_t l = 0; l < levels; ++l) {
        s.level_start[l] = m;
        Vec sum = Vec::Zero();
        std::uint32_t count = 0;
        for (; m < members.size() && level[m] == first_level + l; ++m, ++count) sum += position(p, m);
        if (count > 0) path.set(1 + filled++, sum / static_cast<float>(count));
    }
    s.level_start[levels] = m;
    if (filled < 2) {
        Vec mean = Vec::Zero();
        for (std::uint32_t k = 0; k < members.size(); ++k) mean += position(p, k);
        mean /= static_cast<float>(members.size());
        Eigen::Matrix3f cov = Eigen::Matrix3f::Zero();
        for (std::uint32_t k = 0; k < members.size(); ++k) {
            const Vec d = position(p, k) - mean;
            cov += d * d.transpose();
        }
        Vec axis = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f>(cov).eigenvectors().col(2);
        if (!(axis.squaredNorm() > 0.5f)) axis = -Vec::UnitY();
        float lo = 0, hi = 0;
        for (std::uint32_t k = 0; k < members.size(); ++k) {
            const float t = (position(p, k) - mean).dot(axis);
            lo = std::min(lo, t), hi = std::max(hi, t);
        }
        if (hi - lo < 1e-6f) lo -= 1e-6f, hi += 1e-6f;  // one particle: a sphere around it
        path.set(0, mean + lo * axis), path.set(1, mean + hi * axis);
        path.points = 2;
        path.measure();
        return path;
    }
    // Two passes of (1/4, 1/2, 1/4) over the inner centroids, whose jitter would bend the rings.
    for (int pass = 0; pass < 2; ++pass) {
        Vec prev = path.at(1);
        for (std::uint32_t i = 2; i < filled; ++i) {
            const Vec here = path.at(i);
            path.set(i, 0.25f * prev + 0.5f * here + 0.25f * path.at(i + 1));
            prev = here;
        }
    }
    // Reach back to the farthest centre of the first level and on to that of the last.
    const Vec t0 = (path.at(2) - path.at(1)).normalized();
    const Vec t1 = (path.at(filled) - path.at(filled - 1)).normalized();
    float back = 0, ahead = 0;
    for (std::uint32_t k = 0; k < s.level_start[1]; ++k)
        back = std::max(back, -(position(p, k) - path.at(1)).dot(t0));
    for (std::uint32_t k = s.level_start[levels - 1]; k < members.size(); ++k)
        ahead = std::max(ahead, (position(p, k) - path.at(filled)).dot(t1));
    path.set(0, path.at(1) - back * t0);
    path.set(filled + 1, path.at(filled) + ahead * t1);
    path.points = filled + 2;
    path.first_level_point = 1;
    path.measure();
    return path;
}

// A ring's frame in RingScratch::frames: its plane (the tangent and the offset that make t . x + w the
// height over it), its centre, and the plane's two axes.
constexpr std::size_t kPlane = 0, kCentre = 4, kNormal = 8, kBinormal = 12;
// A padding plane's offset: no sphere is within a radius of it.
constexpr float kNoPlane = 1e30f;

// Radii of one ring, kept in the cylinder's block until the positions are written: the side vertices'
// normal x holds r(theta_k).
struct RingSlots {
    const CylinderLayout& layout;
    std::span<float> v;
    float* side(std::uint32_t ring, std::uint32_t k) const {
        return v.data() + 6 * std::size_t(layout.side_vertex(ring, k));
    }
    float* top(std::uint32_t ring) const { return v.data() + 6 * std::size_t(layout.top_pole(ring)); }
    float* bottom(std::uint32_t ring) const { return v.data() + 6 * std::size_t(layout.bottom_pole(ring)); }
    static void put(float* at, const Vec& a) { at[0] = a.x(), at[1] = a.y(), at[2] = a.z(); }
    static Vec get(const float* at) { return {at[0], at[1], at[2]}; }
};

}  // namespace

OrientedTube oriented_rings(ConstPositions p, std::span<const std::uint32_t> members,
                            std::span<const std::uint32_t> level, std::uint32_t first_level,
                            std::uint32_t levels, const OrientedRingParams& params, const RingScratch& s,
                            std::span<float> vertices) {
    const CylinderLayout& layout = params.layout;
    const std::uint32_t u = layout.u;
    const float radius = params.radius, r2 = radius * radius;
    // The branch's positions in its own order: the ring loops below read them in sequence.
    for (std::size_t k = 0; k < members.size(); ++k)
        s.member_x[k] = p.x[members[k]], s.member_y[k] = p.y[members[k]], s.member_z[k] = p.z[members[k]];
    const ConstPositions local{s.member_x.first(members.size()), s.member_y.first(members.size()),
                               s.member_z.first(members.size())};
    const Path path = build_path(local, members, level, first_level, levels, s);
    const float length = path.length();
    const float spacing = std::max(params.ring_spacing, 1e-9f);
    const auto rings = static_cast<std::uint32_t>(
        std::clamp(std::ceil(length / spacing) + 1.0f, 2.0f, static_cast<float>(layout.v)));
    const float half_window = 0.5f * params.level_width;
    const RingSlots slots{layout, vertices};

    // Ring frames, in the cylinder's block until the positions are written.
    Vec normal = Vec::Zero();
    std::uint32_t at_centre = 0, at_back = 0, at_ahead = 0;
    for (std::uint32_t ring = 0; ring < rings; ++ring) {
        const float t = length * static_cast<float>(ring) / static_cast<float>(rings - 1);
        float index = 0, ignored = 0;
        const Vec centre = path.point(t, index, at_centre);
        const Vec back = path.point(std::max(t - half_window, 0.0f), ignored, at_back);
        Vec tangent = path.point(std::min(t + half_window, length), ignored, at_ahead) - back;
        tangent = tangent.squaredNorm() > 0 ? tangent.normalized() : Vec(-Vec::UnitY());
        normal = ring == 0 ? any_normal(tangent) : normal - normal.dot(tangent) * tangent;
        if (!(normal.squaredNorm() > 1e-12f)) normal = any_normal(tangent);
        normal.normalize();
        const Vec binormal = tangent.cross(normal);  // normal x binormal = tangent: the pool's winding
        float* f = s.frames.data() + kFrameFloats * std::size_t(ring);
        RingSlots::put(f + kPlane, tangent), f[kPlane + 3] = -centre.dot(tangent);
        RingSlots::put(f + kCentre, centre);
        RingSlots::put(f + kNormal, normal), RingSlots::put(f + kBinormal, binormal);
    }

    // Which ring planes each sphere cuts (|h| < r, h its centre's height over the plane): a run of
    // rings around its place on the path, looked for first among the eight around the previous
    // sphere's (members come by level, so along the path), four planes to an SSE register: the planes'
    // coefficients by ring, three rings of padding before and five after that no sphere cuts.
    const std::size_t stride = layout.v + kPlanePadding;
    float* const plane[4] = {s.planes.data(), s.planes.data() + stride, s.planes.data() + 2 * stride,
                             s.planes.data() + 3 * stride};
    for (std::uint32_t i = 0; i < rings + kPlanePadding; ++i) {
        const bool real = i >= 3 && i < rings + 3;
        const float* f = s.frames.data() + kFrameFloats * std::size_t(real ? i - 3 : 0) + kPlane;
        for (int c = 0; c < 4; ++c) plane[c][i] = real ? f[c] : (c == 3 ? kNoPlane : 0.0f);
    }
    const auto height = [&](const Vec& x, std::uint32_t ring) {
        const std::uint32_t i = ring + 3;
        return plane[0][i] * x.x() + plane[1][i] * x.y() + plane[2][i] * x.z() + plane[3][i];
    };
    const auto cut = [&](const Vec& x, std::uint32_t ring) { return std::abs(height(x, ring)) < radius; };
    const __m128 lo_h = _mm_set1_ps(-radius), hi_h = _mm_set1_ps(radius);
    // ring_first counts by a difference array first: +1 where a sphere's run starts, -1 past its end.
    const std::span<std::uint32_t> ring_first = s.ring_first.first(rings + 1);
    std::fill(ring_first.begin(), ring_first.end(), 0u);
    std::uint32_t walk = 0;
    for (std::uint32_t k = 0; k < members.size(); ++k) {
        const Vec x = position(local, k);
        const __m128 vx = _mm_set1_ps(x.x()), vy = _mm_set1_ps(x.y()), vz = _mm_set1_ps(x.z());
        std::uint32_t cuts = 0;  // bit o: ring walk + o - 3
        for (std::uint32_t half = 0; half < 2; ++half) {
            const std::size_t i = walk + 4 * half;
            __m128 h = _mm_mul_ps(_mm_loadu_ps(plane[0] + i), vx);
            h = _mm_add_ps(h, _mm_mul_ps(_mm_loadu_ps(plane[1] + i), vy));
            h = _mm_add_ps(h, _mm_mul_ps(_mm_loadu_ps(plane[2] + i), vz));
            h = _mm_add_ps(h, _mm_loadu_ps(plane[3] + i));
            const __m128 in = _mm_and_ps(_mm_cmplt_ps(h, hi_h), _mm_cmpgt_ps(h, lo_h));
            cuts |= static_cast<std::uint32_t>(_mm_movemask_ps(in)) << (4 * half);
        }
        std::uint32_t lo = walk, count = 0;
        bool open_below = true, open_above = true;  // the run may go on past the rings looked at
        if (cuts != 0) {
            const auto first = static_cast<std::uint32_t>(std::countr_zero(cuts));
            count = static_cast<std::uint32_t>(std::countr_one(cuts >> first));
            lo = walk + first - 3;
            open_below = first == 0, open_above = first + count == 8;
        } else {  // none there (a jump between beads, or a gap between stretched rings): walk to them
            float h = height(x, walk);
            while (h >= radius && walk + 1 < rings) h = height(x, ++walk);
            while (h <= -radius && walk > 0) h = height(x, --walk);
            lo = walk, count = std::abs(h) < radius ? 1 : 0;
        }
        if (count > 0 && open_below)
            while (lo > 0 && count < kMaxRingsPerSphere && cut(x, lo - 1)) --lo, ++count;
        if (count > 0 && open_above)
            while (lo + count < rings && count < kMaxRingsPerSphere && cut(x, lo + count)) ++count;
        count = std::min(count, kMaxRingsPerSphere);
        if (count > 0) walk = lo;
        s.cut_first[k] = lo, s.cut_count[k] = static_cast<std::uint8_t>(count);
        ring_first[lo] += 1, ring_first[lo + count] -= 1;
    }
    // Coverage per ring, then where each ring's circles start.
    for (std::uint32_t ring = 1; ring < rings; ++ring) ring_first[ring] += ring_first[ring - 1];
    for (std::uint32_t ring = rings; ring > 0; --ring) ring_first[ring] = ring_first[ring - 1];
    ring_first[0] = 0;
    for (std::uint32_t ring = 0; ring < rings; ++ring) ring_first[ring + 1] += ring_first[ring];
    const std::span<std::uint32_t> cursor = s.ring_cursor.first(rings);
    std::copy_n(ring_first.begin(), rings, cursor.begin());
    float reach_first = radius, reach_last = radius;
    for (std::uint32_t k = 0; k < members.size(); ++k) {
        const Vec x = position(local, k);
        for (std::uint32_t ring = s.cut_first[k]; ring < s.cut_first[k] + s.cut_count[k]; ++ring) {
            const float* f = s.frames.data() + kFrameFloats * std::size_t(ring);
            const Vec d = x - RingSlots::get(f + kCentre);
            const float h = height(x, ring);
            const std::uint32_t c = cursor[ring]++;
            s.circle_x[c] = d.dot(RingSlots::get(f + kNormal));
            s.circle_z[c] = d.dot(RingSlots::get(f + kBinormal));
            s.circle_rho[c] = std::sqrt(std::max(r2 - h * h, 0.0f));
            if (ring == 0) reach_first = c == ring_first[0] ? radius - h : std::max(reach_first, radius - h);
            if (ring == rings - 1)
                reach_last = c == ring_first[ring] ? radius + h : std::max(reach_last, radius + h);
        }
    }

    std::array<float, kMaxRingVertices> r, tmp;
    std::uint32_t filled = 0;
    for (std::uint32_t ring = 0; ring < rings; ++ring) {
        const std::uint32_t begin = ring_first[ring], circles = ring_first[ring + 1] - begin;
        const std::span<float> rs(r.data(), u), ts(tmp.data(), u);
        if (circles > 0) {
            const CirclesView view{s.circle_x.subspan(begin, circles), s.circle_z.subspan(begin, circles),
                                   s.circle_rho.subspan(begin, circles)};
            if (params.section.function == RadialFunction::kCircleMaxima) {
                circle_maxima(view, params.angles, rs);
                smooth_cyclic(rs, params.section.smoothing_iterations, ts);
            } else {
                gaussian_blend(view, params.angles, params.section.tension, rs, ts);
            }
            ++filled;
        } else {
            std::fill(rs.begin(), rs.end(), -1.0f);  // none: filled in from the neighbours below
        }
        for (std::uint32_t k = 0; k < u; ++k) slots.side(ring, k)[3] = r[k];
    }

    // Rings no sphere cut: the radii of the rings that have some, linearly between them.
    for (std::uint32_t ring = 0; ring < rings; ++ring) {
        if (slots.side(ring, 0)[3] >= 0) continue;
        std::uint32_t before = ring, after = ring;
        while (before > 0 && slots.side(before, 0)[3] < 0) --before;
        while (after + 1 < rings && slots.side(after, 0)[3] < 0) ++after;
        const bool has_before = slots.side(before, 0)[3] >= 0, has_after = slots.side(after, 0)[3] >= 0;
        for (std::uint32_t k = 0; k < u; ++k) {
            float value = radius;
            if (filled > 0 && has_before && has_after) {
                const float f = static_cast<float>(ring - before) / static_cast<float>(after - before);
                value = slots.side(before, k)[3] + f * (slots.side(after, k)[3] - slots.side(before, k)[3]);
            } else if (filled > 0) {
                value = slots.side(has_before ? before : after, k)[3];
            }
            slots.side(ring, k)[3] = value;
        }
    }

    float widest = 0;
    for (std::uint32_t ring = 0; ring < rings; ++ring) {
        const float* f = s.frames.data() + kFrameFloats * std::size_t(ring);
        const Vec centre = RingSlots::get(f + kCentre), tangent = RingSlots::get(f + kPlane);
        const Vec n = RingSlots::get(f + kNormal), b = RingSlots::get(f + kBinormal);
        float sum = 0;
        for (std::uint32_t k = 0; k < u; ++k) {
            float* v = slots.side(ring, k);
            sum += v[3];
            RingSlots::put(v, centre + v[3] * (params.angles.cos_t[k] * n + params.angles.sin_t[k] * b));
        }
        widest = std::max(widest, sum / static_cast<float>(u));
        // Inner rings' poles are never drawn; they stay at the centre so the block is deterministic.
        const float back = ring == 0 ? std::min(reach_first, 2 * radius) : 0.0f;
        const float ahead = ring == rings - 1 ? std::min(reach_last, 2 * radius) : 0.0f;
        RingSlots::put(slots.top(ring), centre - back * tangent);
        RingSlots::put(slots.bottom(ring), centre + ahead * tangent);
    }
    return {rings, length, widest};
}

}  // namespace rivulet
