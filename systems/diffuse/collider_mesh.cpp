#include "systems/diffuse/collider_mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <utility>

#include "jobs/segment_triangle.h"

namespace rivulet {
namespace {

// Enough bounces for a particle thrown into a concave corner; beyond that it is parked at its first hit.
constexpr int kMaxBounces = 4;
// Stand-off from the surface as a fraction of the bounds diagonal: far above float rounding at the scales a
// scene moves colliders by, far below anything visible.
constexpr float kSkinFraction = 1e-4f;
// The largest grid axis has about this many cells per cube root of the triangle count, so a cell holds a
// handful of triangles whatever the mesh.
constexpr float kCellsPerCubeRoot = 1.5f;
constexpr int kMaxCellsPerAxis = 32;

float comp(Vec3f v, int axis) {
    return axis == 0 ? v.x : axis == 1 ? v.y : v.z;
}

Vec3f fetch(const std::vector<float>& p, std::uint32_t i) {
    return {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
}

void push_corner(std::vector<float>& out, Vec3f v) {
    out.insert(out.end(), {v.x, v.y, v.z});
}

// Winding is fixed up from geometry rather than trusted from a hand-typed table: a convex solid around the
// origin is outward-facing exactly when each face normal agrees with its centroid.
void push_outward(std::vector<float>& out, Vec3f a, Vec3f b, Vec3f c) {
    if (dot(cross(b - a, c - a), a + b + c) < 0) std::swap(b, c);
    push_corner(out, a);
    push_corner(out, b);
    push_corner(out, c);
}

std::vector<float> icosphere_corners(float radius, int subdivisions) {
    const float g = 1.6180339887f;  // golden ratio: the icosahedron's vertices are (0, ±1, ±g) cycled
    std::vector<float> pos;
    for (const Vec3f v : {Vec3f{-1, g, 0}, Vec3f{1, g, 0}, Vec3f{-1, -g, 0}, Vec3f{1, -g, 0}, Vec3f{0, -1, g},
                          Vec3f{0, 1, g}, Vec3f{0, -1, -g}, Vec3f{0, 1, -g}, Vec3f{g, 0, -1}, Vec3f{g, 0, 1},
                          Vec3f{-g, 0, -1}, Vec3f{-g, 0, 1}}) {
        push_corner(pos, normalize(v));
    }
    std::vector<std::uint32_t> faces = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                                        4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                                        6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
    for (int s = 0; s < subdivisions; ++s) {
        // Midpoints are shared by the two faces of an edge so the surface stays welded (closed).
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
        auto mid = [&](std::uint32_t a, std::uint32_t b) {
            const std::pair<std::uint32_t, std::uint32_t> key{std::min(a, b), std::max(a, b)};
            const auto it = midpoint.find(key);
            if (it != midpoint.end()) return it->second;
            push_corner(pos, normalize(fetch(pos, a) + fetch(pos, b)));
            const auto m = static_cast<std::uint32_t>(pos.size() / 3 - 1);
            midpoint.emplace(key, m);
            return m;
        };
        std::vector<std::uint32_t> next;
        next.reserve(faces.size() * 4);
        for (std::size_t f = 0; f < faces.size(); f += 3) {
            const std::uint32_t a = faces[f], b = faces[f + 1], c = faces[f + 2];
            const std::uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        faces = std::move(next);
    }
    std::vector<float> corners;
    corners.reserve(faces.size() * 3);
    for (std::size_t f = 0; f < faces.size(); f += 3) {
        push_outward(corners, fetch(pos, faces[f]) * radius, fetch(pos, faces[f + 1]) * radius,
                     fetch(pos, faces[f + 2]) * radius);
    }
    return corners;
}

std::vector<float> box_corners(Vec3f h) {
    std::array<Vec3f, 8> v;
    for (int i = 0; i < 8; ++i) v[i] = {(i & 1) ? h.x : -h.x, (i & 2) ? h.y : -h.y, (i & 4) ? h.z : -h.z};
    // Two triangles per face, as quads (a, b, c, d) around the face.
    const int quads[6][4] = {{0, 2, 6, 4}, {1, 3, 7, 5}, {0, 1, 5, 4},
                             {2, 3, 7, 6}, {0, 1, 3, 2}, {4, 5, 7, 6}};
    std::vector<float> corners;
    for (const auto& q : quads) {
        push_outward(corners, v[q[0]], v[q[1]], v[q[2]]);
        push_outward(corners, v[q[0]], v[q[2]], v[q[3]]);
    }
    return corners;
}

// Lexicographic order on positions: gives every edge one direction whichever triangle asks, so both
// triangles of an edge compute bit-identical orientation values for it (even for unwelded meshes).
bool position_less(Vec3f a, Vec3f b) {
    if (a.x != b.x) return a.x < b.x;
    if (a.y != b.y) return a.y < b.y;
    return a.z < b.z;
}

// Orientation of (py, pz) against the yz projection of edge u -> v, in double from float inputs, and the
// sign of that value after perturbing the point by (eps, eps^2) (simulation of simplicity), so that a ray
// through an edge or vertex belongs to exactly one side of every edge, consistently across triangles.
struct EdgeSide {
    double value;  // unperturbed, for the crossing's position
    int sign;      // perturbed: never 0 unless the edge projects to a point
};

EdgeSide edge_side(Vec3f u, Vec3f v, double py, double pz) {
    const bool flip = position_less(v, u);
    if (flip) std::swap(u, v);
    const double wy = double(v.y) - u.y, wz = double(v.z) - u.z;
    double e = wy * (pz - u.z) - wz * (py - u.y);
    int s = e > 0 ? 1 : e < 0 ? -1 : 0;
    // Perturbing the point by (eps, eps^2) adds -wz * eps + wy * eps^2.
    if (s == 0) s = wz != 0 ? (wz > 0 ? -1 : 1) : (wy > 0 ? 1 : wy < 0 ? -1 : 0);
    if (flip) {
        e = -e;
        s = -s;
    }
    return {e, s};
}

}  // namespace

ColliderMesh ColliderMesh::sphere(float radius) {
    if (!(radius > 0) || !std::isfinite(radius))
        throw std::invalid_argument("ColliderMesh::sphere: radius must be > 0");
    return ColliderMesh(icosphere_corners(radius, 3));
}

ColliderMesh ColliderMesh::box(Vec3f half_extents) {
    const Vec3f h = half_extents;
    if (!(h.x > 0 && h.y > 0 && h.z > 0) || !finite(h)) {
        throw std::invalid_argument("ColliderMesh::box: half extents must be > 0");
    }
    return ColliderMesh(box_corners(h));
}

ColliderMesh ColliderMesh::from_mesh(const ColoredMesh& m) {
    if (m.triangle_count() == 0 || m.indices.size() % 3 != 0 || m.positions.size() % 3 != 0) {
        throw std::invalid_argument("ColliderMesh::from_mesh: no triangles");
    }
    for (const float f : m.positions) {
        if (!std::isfinite(f)) throw std::invalid_argument("ColliderMesh::from_mesh: non-finite position");
    }
    std::vector<float> corners;
    corners.reserve(m.indices.size() * 3);
    for (const std::uint32_t i : m.indices) {
        if (i >= m.vertex_count()) throw std::invalid_argument("ColliderMesh::from_mesh: index out of range");
        push_corner(corners, fetch(m.positions, i));
    }
    return ColliderMesh(std::move(corners));
}

ColliderMesh::ColliderMesh(std::vector<float> corners) : corners_(std::move(corners)) {
    const std::size_t tris = corners_.size() / 9;
    normals_.resize(tris);
    offsets_.resize(tris);
    constexpr float kInf = std::numeric_limits<float>::infinity();
    lo_ = {kInf, kInf, kInf};
    hi_ = {-kInf, -kInf, -kInf};
    for (std::size_t t = 0; t < tris; ++t) {
        const Vec3f a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        normals_[t] = normalize(cross(b - a, c - a));
        offsets_[t] = dot(normals_[t], a);
        for (const Vec3f p : {a, b, c}) {
            lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y), std::min(lo_.z, p.z)};
            hi_ = {std::max(hi_.x, p.x), std::max(hi_.y, p.y), std::max(hi_.z, p.z)};
        }
    }
    const Vec3f ext = hi_ - lo_;
    float longest = std::max({ext.x, ext.y, ext.z});
    if (!(longest > 0)) longest = std::max({std::abs(lo_.x), std::abs(lo_.y), std::abs(lo_.z), 1.0f});
    skin_ = kSkinFraction * std::max(length(ext), longest);
    reach_centre_ = (lo_ + hi_) * 0.5f;
    float farthest = 0;
    for (std::size_t k = 0; k + 2 < corners_.size(); k += 3)
        farthest =
            std::max(farthest, length(Vec3f{corners_[k], corners_[k + 1], corners_[k + 2]} - reach_centre_));
    reach_radius_ = farthest * 1.001f + 2 * skin_;

    // The grid reaches a little past the triangles so that segments padded by a fraction of the skin and
    // crossings right at the bounds stay inside it.
    const float margin = 0.01f * longest;
    grid_lo_ = lo_ - Vec3f{margin, margin, margin};
    const Vec3f span = ext + Vec3f{2 * margin, 2 * margin, 2 * margin};
    const int cells_long =
        std::clamp(static_cast<int>(std::ceil(kCellsPerCubeRoot * std::cbrt(static_cast<float>(tris)))), 1,
                   kMaxCellsPerAxis);
    const float target = (longest + 2 * margin) / static_cast<float>(cells_long);
    for (int a = 0; a < 3; ++a) {
        dims_[a] = std::clamp(static_cast<int>(std::ceil(comp(span, a) / target)), 1, kMaxCellsPerAxis);
    }
    cell_size_ = {span.x / static_cast<float>(dims_[0]), span.y / static_cast<float>(dims_[1]),
                  span.z / static_cast<float>(dims_[2])};
    inv_cell_ = {1 / cell_size_.x, 1 / cell_size_.y, 1 / cell_size_.z};

    // Bins use each triangle's box widened a little, so rounding in a query's cell lookup (a crossing point
    // computed in double, a grid walk's boundary parameters) cannot land it in a cell that lacks the
    // triangle.
    const float widen = 1e-3f * std::min({cell_size_.x, cell_size_.y, cell_size_.z});
    const std::size_t cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
    auto cell_range = [&](std::size_t t, int lo[3], int hi[3]) {
        const Vec3f a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
        for (int k = 0; k < 3; ++k) {
            lo[k] = cell_of(std::min({comp(a, k), comp(b, k), comp(c, k)}) - widen, k);
            hi[k] = cell_of(std::max({comp(a, k), comp(b, k), comp(c, k)}) + widen, k);
        }
    };
    cell_start_.assign(cells + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<std::uint32_t> fill;
        if (pass == 1) {
            for (std::size_t i = 0; i < cells; ++i) cell_start_[i + 1] += cell_start_[i];
            cell_tris_.resize(cell_start_[cells]);
            fill.assign(cell_start_.begin(), cell_start_.end() - 1);
        }
        for (std::size_t t = 0; t < tris; ++t) {
            int lo[3], hi[3];
            cell_range(t, lo, hi);
            for (int z = lo[2]; z <= hi[2]; ++z) {
                for (int y = lo[1]; y <= hi[1]; ++y) {
                    for (int x = lo[0]; x <= hi[0]; ++x) {
                        const std::size_t c = cell_index(x, y, z);
                        if (pass == 0) {
                            ++cell_start_[c + 1];
                        } else {
                            cell_tris_[fill[c]++] = static_cast<std::uint32_t>(t);
                        }
                    }
                }
            }
        }
    }
    // A cell no (widened) triangle touches lies wholly on one side; its centre is a safe sample, at least
    // the widening away from the surface.
    cell_class_.assign(cells, kMixed);
    for (int z = 0; z < dims_[2]; ++z) {
        for (int y = 0; y < dims_[1]; ++y) {
            for (int x = 0; x < dims_[0]; ++x) {
                const std::size_t c = cell_index(x, y, z);
                if (cell_start_[c] != cell_start_[c + 1]) continue;
                const Vec3f centre = grid_lo_ + Vec3f{cell_size_.x * (static_cast<float>(x) + 0.5f),
                                                      cell_size_.y * (static_cast<float>(y) + 0.5f),
                                                      cell_size_.z * (static_cast<float>(z) + 0.5f)};
                cell_class_[c] = ray_parity(centre, false) ? kInside : kOutside;
            }
        }
    }
}

int ColliderMesh::cell_of(float x, int axis) const {
    const float f = (x - comp(grid_lo_, axis)) * comp(inv_cell_, axis);
    if (!(f >= 1)) return 0;  // also NaN
    const int last = dims_[axis] - 1;
    return f >= static_cast<float>(last) ? last : static_cast<int>(f);
}

bool ColliderMesh::contains(Vec3f p) const {
    return ray_parity(p, true);
}

bool ColliderMesh::ray_parity(Vec3f p, bool use_classes) const {
    if (!(p.x <= hi_.x && p.y >= lo_.y && p.y <= hi_.y && p.z >= lo_.z && p.z <= hi_.z)) return false;
    const int iy = cell_of(p.y, 1), iz = cell_of(p.z, 2);
    const float py = p.y, pz = p.z;
    bool inside = false;
    for (int ix = cell_of(p.x, 0); ix < dims_[0]; ++ix) {
        const std::size_t cell = cell_index(ix, iy, iz);
        // No triangle reaches this cell, so the ray's remaining crossings (all beyond it) add up to its side.
        if (use_classes && cell_class_[cell] != kMixed) return inside != (cell_class_[cell] == kInside);
        for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
            const std::uint32_t t = cell_tris_[k];
            const Vec3f a = corner(t, 0), b = corner(t, 1), c = corner(t, 2);
            if ((py < a.y && py < b.y && py < c.y) || (py > a.y && py > b.y && py > c.y) ||
                (pz < a.z && pz < b.z && pz < c.z) || (pz > a.z && pz > b.z && pz > c.z)) {
                continue;
            }
            const EdgeSide wa = edge_side(b, c, py, pz), wb = edge_side(c, a, py, pz),
                           wc = edge_side(a, b, py, pz);
            if (wa.sign == 0 || wa.sign != wb.sign || wa.sign != wc.sign) continue;
            // Where the +x ray meets the triangle's plane: the edge values are its barycentric weights.
            const double sum = wa.value + wb.value + wc.value;
            const double x = sum != 0 ? (wa.value * a.x + wb.value * b.x + wc.value * c.x) / sum
                                      : std::min({a.x, b.x, c.x});
            if (!(x > p.x)) continue;
            // A triangle listed in several cells of the row counts only in the cell holding its crossing.
            if (cell_of(static_cast<float>(x), 0) != ix) continue;
            inside = !inside;
        }
    }
    return inside;
}

bool ColliderMesh::triangle_touches_box(std::size_t tri, Vec3f center, Vec3f half) const {
    // Separating axes (Akenine-Möller): the box's faces, the triangle's plane, and the nine edge crosses.
    const Vec3f v[3] = {corner(tri, 0) - center, corner(tri, 1) - center, corner(tri, 2) - center};
    auto separated = [&](Vec3f axis) {
        const float p0 = dot(v[0], axis), p1 = dot(v[1], axis), p2 = dot(v[2], axis);
        const float r = half.x * std::abs(axis.x) + half.y * std::abs(axis.y) + half.z * std::abs(axis.z);
        return std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r;
    };
    if (separated({1, 0, 0}) || separated({0, 1, 0}) || separated({0, 0, 1})) return false;
    const Vec3f e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
    if (separated(cross(e[0], e[1]))) return false;
    for (const Vec3f& edge : e) {
        if (separated({0, -edge.z, edge.y}) || separated({edge.z, 0, -edge.x}) ||
            separated({-edge.y, edge.x, 0})) {
            return false;
        }
    }
    return true;
}

bool ColliderMesh::overlaps_box(Vec3f lo, Vec3f hi) const {
    if (!(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z)) return false;  // empty (or NaN)
    if (hi.x < lo_.x || hi.y < lo_.y || hi.z < lo_.z || lo.x > hi_.x || lo.y > hi_.y || lo.z > hi_.z)
        return false;
    // Widened a little so that rounding in the separating-axis test errs towards "touches".
    const float widen = 0.1f * skin_;
    const Vec3f center = (lo + hi) * 0.5f;
    const Vec3f half = (hi - lo) * 0.5f + Vec3f{widen, widen, widen};
    const Vec3f qlo = lo - Vec3f{widen, widen, widen}, qhi = hi + Vec3f{widen, widen, widen};
    const int x0 = cell_of(qlo.x, 0), x1 = cell_of(qhi.x, 0), y0 = cell_of(qlo.y, 1), y1 = cell_of(qhi.y, 1);
    const int z0 = cell_of(qlo.z, 2), z1 = cell_of(qhi.z, 2);
    for (int z = z0; z <= z1; ++z) {
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const std::size_t cell = cell_index(x, y, z);
                for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
                    if (triangle_touches_box(cell_tris_[k], center, half)) return true;
                }
            }
        }
    }
    // No surface inside the box, so the box is wholly inside or wholly outside the solid: a box reaching
    // past the bounds is outside, any other is decided by its centre.
    if (lo.x < lo_.x || lo.y < lo_.y || lo.z < lo_.z || hi.x > hi_.x || hi.y > hi_.y || hi.z > hi_.z)
        return false;
    return contains(center);
}

bool ColliderMesh::first_entry(Vec3f p0, Vec3f p1, Entry& hit) const {
    const Vec3f d = p1 - p0;
    const float len = length(d);
    if (!(len > 0) || !std::isfinite(len)) return false;
    // Padded at both ends: a particle resting just short of the surface, or a hair inside it after rounding,
    // still sees the crossing.
    const Vec3f pad = d * (0.25f * skin_ / len);
    const Vec3f q0 = p0 - pad, q1 = p1 + pad;
    const double o[3] = {q0.x, q0.y, q0.z};
    const double dir[3] = {double(q1.x) - q0.x, double(q1.y) - q0.y, double(q1.z) - q0.z};

    // Clip to the grid, then walk the cells the segment passes through in order (Amanatides & Woo), stopping
    // once the nearest crossing found lies before the cell being left.
    double t_in = 0, t_out = 1;
    for (int a = 0; a < 3; ++a) {
        const double g0 = comp(grid_lo_, a), g1 = g0 + double(comp(cell_size_, a)) * dims_[a];
        if (dir[a] == 0) {
            if (o[a] < g0 || o[a] > g1) return false;
            continue;
        }
        double ta = (g0 - o[a]) / dir[a], tb = (g1 - o[a]) / dir[a];
        if (ta > tb) std::swap(ta, tb);
        t_in = std::max(t_in, ta);
        t_out = std::min(t_out, tb);
    }
    if (!(t_in <= t_out)) return false;

    int cell[3], step[3];
    double t_next[3], t_delta[3];
    for (int a = 0; a < 3; ++a) {
        cell[a] = cell_of(static_cast<float>(o[a] + dir[a] * t_in), a);
        const double size = comp(cell_size_, a);
        if (dir[a] > 0) {
            step[a] = 1;
            t_next[a] = (comp(grid_lo_, a) + size * (cell[a] + 1) - o[a]) / dir[a];
            t_delta[a] = size / dir[a];
        } else if (dir[a] < 0) {
            step[a] = -1;
            t_next[a] = (comp(grid_lo_, a) + size * cell[a] - o[a]) / dir[a];
            t_delta[a] = -size / dir[a];
        } else {
            step[a] = 0;
            t_next[a] = t_delta[a] = std::numeric_limits<double>::infinity();
        }
    }

    // Plane rejection before the exact test: an entry needs q0 in front of the plane and q1 behind it. The
    // slack covers float rounding of the plane distances (relative to the distances involved, the segment's
    // length at most), so nothing the exact test would find is skipped.
    const float slack = skin_ + 1e-6f * len;
    double best_t = std::numeric_limits<double>::infinity();
    std::uint32_t best = 0;
    for (int guard = dims_[0] + dims_[1] + dims_[2] + 3; guard > 0; --guard) {
        const std::size_t c = cell_index(cell[0], cell[1], cell[2]);
        for (std::uint32_t k = cell_start_[c]; k < cell_start_[c + 1]; ++k) {
            const std::uint32_t t = cell_tris_[k];
            if (dot(normals_[t], q0) - offsets_[t] < -slack || dot(normals_[t], q1) - offsets_[t] > slack)
                continue;
            SegmentCrossing x;
            if (segment_crosses_triangle(q0, q1, corner(t, 0), corner(t, 1), corner(t, 2), x) && x.front &&
                x.t < best_t) {
                best_t = x.t;
                best = t;
            }
        }
        const int a =
            t_next[0] <= t_next[1] ? (t_next[0] <= t_next[2] ? 0 : 2) : (t_next[1] <= t_next[2] ? 1 : 2);
        if (best_t <= t_next[a] || t_next[a] >= t_out) break;
        cell[a] += step[a];
        if (cell[a] < 0 || cell[a] >= dims_[a]) break;
        t_next[a] += t_delta[a];
    }
    if (!(best_t <= 1)) return false;
    hit.point = {static_cast<float>(o[0] + dir[0] * best_t), static_cast<float>(o[1] + dir[1] * best_t),
                 static_cast<float>(o[2] + dir[2] * best_t)};
    hit.normal = normals_[best];
    return true;
}

bool ColliderMesh::collide(Vec3f p0, Vec3f& p1, Vec3f& velocity, float restitution) const {
    Entry hit;
    if (!first_entry(p0, p1, hit)) {
        // The walk above should be watertight; this keeps the promise even if rounding opened a gap.
        if (contains(p1) && !contains(p0)) {
            p1 = p0;
            return true;
        }
        return false;
    }
    const float e = restitution > 0 ? restitution : 0;
    const Vec3f first_stop = hit.point + hit.normal * skin_;
    const Vec3f first_velocity = reflect_off_surface(velocity, hit.normal, e);
    Vec3f end = p1, v = velocity;
    bool settled = false;
    for (int bounce = 0; bounce < kMaxBounces && !settled; ++bounce) {
        // The rest of the step, mirrored, restarted a skin off the surface so it cannot re-hit this face.
        const Vec3f rest = reflect_off_surface(end - hit.point, hit.normal, e);
        v = reflect_off_surface(v, hit.normal, e);
        const Vec3f start = hit.point + hit.normal * skin_;
        end = start + rest;
        settled = !first_entry(start, end, hit);
    }
    // Parking is the fallback for a particle still bouncing, and for the rare end point that the skin did
    // not keep out (a feature thinner than the skin).
    if (!settled || contains(end)) {
        end = contains(first_stop) ? p0 : first_stop;
        v = first_velocity;
    }
    p1 = end;
    velocity = v;
    return true;
}

}  // namespace rivulet
