#include "jobs/marching_tables.h"

#include <stdexcept>

namespace rivulet {
namespace {

int corner_bit(int c, int axis) {
    return (c >> axis) & 1;
}

struct Builder {
    MarchingTables t;
    int edge_between[8][8];

    Builder() {
        for (auto& row : edge_between)
            for (int& e : row) e = -1;
        for (int axis = 0; axis < 3; ++axis) {
            const int u = (axis + 1) % 3, w = (axis + 2) % 3;
            for (int idx = 0; idx < 4; ++idx) {
                const int e = axis * 4 + idx;
                const int lo = ((idx & 1) << u) | ((idx >> 1) << w);
                const int hi = lo | (1 << axis);
                t.edge_corner[e] = {static_cast<std::uint8_t>(lo), static_cast<std::uint8_t>(hi)};
                t.edge_axis[e] = static_cast<std::uint8_t>(axis);
                edge_between[lo][hi] = edge_between[hi][lo] = e;
            }
        }
    }

    // Bit 2 * axis + side for each of the two faces holding edge e.
    int faces_of(int e) const {
        const int axis = t.edge_axis[e], lo = t.edge_corner[e][0];
        int mask = 0;
        for (int u = 0; u < 3; ++u)
            if (u != axis) mask |= 1 << (2 * u + corner_bit(lo, u));
        return mask;
    }

    // Corners of face (axis, side) counter-clockwise about its outward normal.
    void face_cycle(int axis, int side, int out[4]) const {
        const int u = (axis + 1) % 3, w = (axis + 2) % 3;  // e_u x e_w = e_axis
        static const int ccw[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (int i = 0; i < 4; ++i) {
            const int q = side ? i : (4 - i) % 4;  // reversed for the -axis face
            out[i] = (side << axis) | (ccw[q][0] << u) | (ccw[q][1] << w);
        }
    }

    // Fills case `m`; `flip` reverses every segment. Returns false if segments do not chain.
    bool build_case(int m, bool flip) {
        int next[12];
        for (int& n : next) n = -1;
        std::uint16_t crossed = 0;
        for (int axis = 0; axis < 3; ++axis)
            for (int side = 0; side < 2; ++side) {
                int c[4];
                face_cycle(axis, side, c);
                bool in[4];
                for (int i = 0; i < 4; ++i) in[i] = (m >> c[i]) & 1;
                for (int i = 0; i < 4; ++i) {
                    if (!in[i] || in[(i + 3) % 4]) continue;  // a run of inside corners starts at i
                    int j = i;
                    while (in[(j + 1) % 4]) j = (j + 1) % 4;
                    const int entry = edge_between[c[(i + 3) % 4]][c[i]];
                    const int exit = edge_between[c[j]][c[(j + 1) % 4]];
                    const int from = flip ? exit : entry, to = flip ? entry : exit;
                    if (next[from] != -1) return false;
                    next[from] = to;
                    crossed = static_cast<std::uint16_t>(crossed | (1u << from) | (1u << to));
                }
            }
        t.edge_mask[m] = crossed;
        int count = 0;
        std::uint16_t used = 0;
        for (int e0 = 0; e0 < 12; ++e0) {
            if (!((crossed >> e0) & 1) || ((used >> e0) & 1)) continue;
            int loop[12], len = 0, e = e0;
            do {
                if (e < 0 || len == 12 || ((used >> e) & 1)) return false;
                used = static_cast<std::uint16_t>(used | (1u << e));
                loop[len++] = e;
                e = next[e];
            } while (e != e0);
            if (len < 3) return false;
            // Fan from the first apex that puts no triangle flat on a cube face (a loop that crosses an
            // ambiguous face twice would otherwise lay a triangle in that face from both sides).
            int apex = -1;
            for (int a = 0; a < len && apex < 0; ++a) {
                bool flat = false;
                for (int i = 1; i + 1 < len && !flat; ++i)
                    flat = (faces_of(loop[a]) & faces_of(loop[(a + i) % len]) &
                            faces_of(loop[(a + i + 1) % len])) != 0;
                if (!flat) apex = a;
            }
            if (apex < 0) return false;
            for (int i = 1; i + 1 < len; ++i) {
                if (count == MarchingTables::kMaxTriangles) return false;
                t.triangles[m][count * 3 + 0] = static_cast<std::int8_t>(loop[apex]);
                t.triangles[m][count * 3 + 1] = static_cast<std::int8_t>(loop[(apex + i) % len]);
                t.triangles[m][count * 3 + 2] = static_cast<std::int8_t>(loop[(apex + i + 1) % len]);
                ++count;
            }
        }
        t.triangle_count[m] = static_cast<std::uint8_t>(count);
        return true;
    }

    // Case 1 (corner 0 inside): its triangle must face away from corner 0, towards (1, 1, 1).
    bool case1_faces_out() const {
        float p[3][3];
        for (int v = 0; v < 3; ++v) {
            const int e = t.triangles[1][v];
            for (int a = 0; a < 3; ++a)
                p[v][a] =
                    0.5f * float(corner_bit(t.edge_corner[e][0], a) + corner_bit(t.edge_corner[e][1], a));
        }
        float u[3], w[3];
        for (int a = 0; a < 3; ++a) u[a] = p[1][a] - p[0][a], w[a] = p[2][a] - p[0][a];
        const float n[3] = {u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]};
        return n[0] + n[1] + n[2] > 0;
    }

    void build() {
        for (bool flip : {false, true}) {
            bool ok = true;
            for (int m = 0; m < 256 && ok; ++m) ok = build_case(m, flip);
            if (ok && case1_faces_out()) return;
        }
        throw std::logic_error("marching tables: inconsistent segment rule");
    }
};

}  // namespace

const MarchingTables& marching_tables() {
    static const MarchingTables tables = [] {
        Builder b;
        b.build();
        return b.t;
    }();
    return tables;
}

}  // namespace rivulet
