#include "jobs/voxelize_columns.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace rivulet {
namespace {

constexpr std::int64_t kOne = std::int64_t{1} << kColumnFixedBits;

// Floor and ceiling of v / kOne for either sign (an arithmetic shift floors).
int floor_fixed(std::int64_t v) {
    return static_cast<int>(v >> kColumnFixedBits);
}
int ceil_fixed(std::int64_t v) {
    return static_cast<int>(-((-v) >> kColumnFixedBits));
}

// One directed edge a -> b of the projection and its edge function E(p) = cross((b - a), (p - a)) in
// (y, z). E is exact, so the two triangles sharing an edge see exactly opposite values.
struct Edge {
    std::int64_t ay, az, dy, dz;
    int tie;  // the sign of E at a column displaced by (+e, +e^2) when E is exactly 0
    Edge(const std::int32_t* a, const std::int32_t* b)
        : ay(a[1]), az(a[2]), dy(std::int64_t{b[1]} - a[1]), dz(std::int64_t{b[2]} - a[2]) {
        // d/dy E = -dz, d/dz E = dy: the e term decides unless the edge is parallel to y.
        tie = dz != 0 ? (dz > 0 ? -1 : 1) : (dy > 0 ? 1 : (dy < 0 ? -1 : 0));
    }
    std::int64_t at(std::int64_t py, std::int64_t pz) const { return dy * (pz - az) - dz * (py - ay); }
};

int side(std::int64_t e, int tie) {
    return e > 0 ? 1 : (e < 0 ? -1 : tie);
}

}  // namespace

ColumnBounds triangle_columns(const std::int32_t* a, const std::int32_t* b, const std::int32_t* c, int ny,
                              int nz) {
    const std::int64_t lo_y = std::min({a[1], b[1], c[1]}), hi_y = std::max({a[1], b[1], c[1]});
    const std::int64_t lo_z = std::min({a[2], b[2], c[2]}), hi_z = std::max({a[2], b[2], c[2]});
    return {std::max(0, ceil_fixed(lo_y)), std::min(ny - 1, floor_fixed(hi_y)), std::max(0, ceil_fixed(lo_z)),
            std::min(nz - 1, floor_fixed(hi_z))};
}

void voxelize_columns(int tz, const VoxelizeColumnsContext& ctx) {
    const int nx = ctx.nx, ny = ctx.ny;
    const int z_begin = tz * ctx.tile, z_end = std::min(ctx.nz, z_begin + ctx.tile);
    if (z_begin >= z_end) return;
    std::uint8_t* const rows = ctx.inside.data() + std::size_t(z_begin) * ny * nx;
    std::memset(rows, 0, std::size_t(z_end - z_begin) * ny * nx);

    // First every crossing marks where the parity flips (xor, so the order of triangles does not
    // matter); then a running xor along each row turns flips into inside runs.
    for (int ty = 0; ty < ctx.tiles_y; ++ty) {
        const std::size_t tile = std::size_t(tz) * ctx.tiles_y + ty;
        const int y_begin = ty * ctx.tile, y_end = std::min(ny, y_begin + ctx.tile);
        for (std::uint32_t k = ctx.tile_start[tile]; k < ctx.tile_start[tile + 1]; ++k) {
            const std::uint32_t t = ctx.tile_triangles[k];
            const std::int32_t* a = &ctx.fixed[3 * std::size_t(ctx.indices[3 * std::size_t(t)])];
            const std::int32_t* b = &ctx.fixed[3 * std::size_t(ctx.indices[3 * std::size_t(t) + 1])];
            const std::int32_t* c = &ctx.fixed[3 * std::size_t(ctx.indices[3 * std::size_t(t) + 2])];
            const Edge ea(b, c), eb(c, a), ec(a, b);  // ea(p) weighs a, eb(p) b, ec(p) c
            const std::int64_t area = ec.at(c[1], c[2]);
            if (area == 0) continue;  // seen edge-on: the perturbed column never lies inside
            const ColumnBounds cb = triangle_columns(a, b, c, ny, ctx.nz);
            const int y0 = std::max(cb.y0, y_begin), y1 = std::min(cb.y1, y_end - 1);
            const int z0 = std::max(cb.z0, z_begin), z1 = std::min(cb.z1, z_end - 1);
            const double inv_area = 1.0 / static_cast<double>(area);
            const double bx = double(b[0]) - a[0], cx = double(c[0]) - a[0];
            for (int iz = z0; iz <= z1; ++iz) {
                const std::int64_t pz = std::int64_t{iz} * kOne;
                for (int iy = y0; iy <= y1; ++iy) {
                    const std::int64_t py = std::int64_t{iy} * kOne;
                    const std::int64_t wa = ea.at(py, pz), wb = eb.at(py, pz), wc = ec.at(py, pz);
                    const int s = side(wa, ea.tie);
                    if (s == 0 || side(wb, eb.tie) != s || side(wc, ec.tie) != s) continue;
                    // Relative to a, so a face of constant x crosses at exactly that x.
                    const double x = a[0] + (double(wb) * bx + double(wc) * cx) * inv_area;
                    const double first = std::ceil(x / double(kOne));  // first centre at or beyond x
                    if (first >= nx) continue;
                    const int ix = first < 0 ? 0 : static_cast<int>(first);
                    rows[(std::size_t(iz - z_begin) * ny + iy) * nx + ix] ^= 1;
                }
            }
        }
    }
    for (std::size_t r = 0; r < std::size_t(z_end - z_begin) * ny; ++r) {
        std::uint8_t* row = rows + r * nx;
        std::uint8_t run = 0;
        for (int ix = 0; ix < nx; ++ix) row[ix] = run ^= row[ix];
    }
}

}  // namespace rivulet
