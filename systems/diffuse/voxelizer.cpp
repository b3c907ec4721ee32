#include "systems/diffuse/voxelizer.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "jobs/voxelize_columns.h"

namespace rivulet {
namespace {

constexpr int kTile = 8;          // columns per tile side: a tile's triangle list is shared by 64 columns
constexpr int kColourSlab = 4;    // voxel layers per colour seeding task
constexpr double kBand = 1.0001;  // seed voxels lie within one cell of the surface (grid units)
constexpr float kFar = std::numeric_limits<float>::infinity();

void validate(const ColoredMesh& mesh, int resolution, int padding) {
    if (resolution < 1 || resolution > kMaxVoxelResolution)
        throw std::invalid_argument("voxelize: resolution " + std::to_string(resolution) +
                                    " is outside [1, " + std::to_string(kMaxVoxelResolution) + "]");
    if (padding < 0 || padding > kMaxVoxelPadding)
        throw std::invalid_argument("voxelize: padding " + std::to_string(padding) + " is outside [0, " +
                                    std::to_string(kMaxVoxelPadding) + "]");
    if (mesh.positions.size() % 3 != 0 || mesh.indices.size() % 3 != 0)
        throw std::invalid_argument(
            "voxelize: positions and indices must hold three values per vertex / "
            "triangle");
    if (mesh.triangle_count() == 0) throw std::invalid_argument("voxelize: the mesh has no triangles");
    if (mesh.triangle_count() > kMaxVoxelizeTriangles)
        throw std::invalid_argument("voxelize: " + std::to_string(mesh.triangle_count()) +
                                    " triangles, more than the limit of " +
                                    std::to_string(kMaxVoxelizeTriangles));
    if (mesh.vertex_count() > std::numeric_limits<std::uint32_t>::max())
        throw std::invalid_argument("voxelize: too many vertices");
    if (!mesh.colors.empty() && mesh.colors.size() != mesh.positions.size())
        throw std::invalid_argument("voxelize: " + std::to_string(mesh.colors.size() / 3) + " colours for " +
                                    std::to_string(mesh.vertex_count()) + " vertices");
    for (float v : mesh.positions)
        if (!std::isfinite(v)) throw std::invalid_argument("voxelize: a vertex coordinate is not finite");
    for (std::uint32_t i : mesh.indices)
        if (i >= mesh.vertex_count())
            throw std::invalid_argument("voxelize: vertex index " + std::to_string(i) + " is out of range (" +
                                        std::to_string(mesh.vertex_count()) + " vertices)");
}

// Watertightness. Vertices with identical positions are welded first (a mesh split at colour or UV seams
// is still closed); triangles that weld to fewer than three vertices have no area and are left out.
void require_closed(const ColoredMesh& mesh) {
    const std::size_t nv = mesh.vertex_count();
    auto key = [&](std::uint32_t v) {
        std::array<std::uint32_t, 3> k;
        for (int a = 0; a < 3; ++a) k[a] = std::bit_cast<std::uint32_t>(mesh.positions[3 * v + a] + 0.0f);
        return k;  // + 0.0f turns -0 into +0
    };
    std::vector<std::uint32_t> order(nv);
    for (std::size_t v = 0; v < nv; ++v) order[v] = static_cast<std::uint32_t>(v);
    tbb::parallel_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
        const auto ka = key(a), kb = key(b);
        return ka != kb ? ka < kb : a < b;
    });
    std::vector<std::uint32_t> weld(nv);
    for (std::size_t i = 0; i < nv; ++i)
        weld[order[i]] = (i > 0 && key(order[i]) == key(order[i - 1])) ? weld[order[i - 1]] : order[i];

    std::vector<std::uint64_t> edges;
    edges.reserve(mesh.indices.size());
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const std::uint32_t v[3] = {weld[mesh.indices[3 * t]], weld[mesh.indices[3 * t + 1]],
                                    weld[mesh.indices[3 * t + 2]]};
        if (v[0] == v[1] || v[1] == v[2] || v[2] == v[0]) continue;
        for (int e = 0; e < 3; ++e) {
            const std::uint64_t a = v[e], b = v[(e + 1) % 3];
            edges.push_back(a < b ? (a << 32 | b) : (b << 32 | a));
        }
    }
    if (edges.empty()) throw std::invalid_argument("voxelize: every triangle of the mesh is degenerate");
    tbb::parallel_sort(edges.begin(), edges.end());
    std::size_t open = 0, crowded = 0;
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i;
        while (j < edges.size() && edges[j] == edges[i]) ++j;
        open += (j - i) == 1;
        crowded += (j - i) > 2;
        i = j;
    }
    if (open != 0 || crowded != 0)
        throw std::invalid_argument("mesh is not closed: " + std::to_string(open) +
                                    " edges bound a hole and " + std::to_string(crowded) +
                                    " edges are shared by more than two triangles; diffuse objects need a "
                                    "watertight mesh");
}

VoxelGridShape grid_shape(const ColoredMesh& mesh, int resolution, int padding) {
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = mesh.positions[a];
    for (std::size_t v = 0; v < mesh.vertex_count(); ++v)
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], double(mesh.positions[3 * v + a]));
            hi[a] = std::max(hi[a], double(mesh.positions[3 * v + a]));
        }
    const double longest = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    if (!(longest > 0))
        throw std::invalid_argument("voxelize: the mesh has no extent (all vertices coincide)");
    VoxelGridShape s;
    s.cell = static_cast<float>(longest / resolution);
    int n[3];
    for (int a = 0; a < 3; ++a) {
        // The small allowance keeps an axis exactly k cells long from rounding up to k + 1.
        const double cells = std::ceil((hi[a] - lo[a]) / s.cell - 1e-4);
        n[a] = std::clamp(static_cast<int>(cells), 1, resolution) + 2 * padding;
    }
    s.nx = n[0], s.ny = n[1], s.nz = n[2];
    s.origin = Vec3f{static_cast<float>(lo[0] - padding * double(s.cell)),
                     static_cast<float>(lo[1] - padding * double(s.cell)),
                     static_cast<float>(lo[2] - padding * double(s.cell))};
    return s;
}

// Grid space: voxel (ix, iy, iz) has its centre at (ix, iy, iz).
struct GridVertices {
    std::vector<double> g;            // xyz per vertex
    std::vector<std::int32_t> fixed;  // g * 2^kColumnFixedBits, rounded
};

GridVertices to_grid(const ColoredMesh& mesh, const VoxelGridShape& s) {
    const std::size_t nv = mesh.vertex_count();
    GridVertices gv{std::vector<double>(3 * nv), std::vector<std::int32_t>(3 * nv)};
    const double origin[3] = {s.origin.x, s.origin.y, s.origin.z};
    const double scale = std::ldexp(1.0, kColumnFixedBits);
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, 3 * nv), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t i = r.begin(); i < r.end(); ++i) {
                const double g = (double(mesh.positions[i]) - origin[i % 3]) / s.cell - 0.5;
                gv.g[i] = g;
                gv.fixed[i] = static_cast<std::int32_t>(
                    std::llround(std::clamp(g, -1.0 * kColumnMaxGrid, 1.0 * kColumnMaxGrid) * scale));
            }
        });
    return gv;
}

// Counting sort of triangles into the tiles their projected column bounds meet, in triangle order.
void bin_tiles(const ColoredMesh& mesh, const GridVertices& gv, VoxelizeColumnsContext& ctx,
               std::vector<std::uint32_t>& start, std::vector<std::uint32_t>& list) {
    const std::size_t tiles = std::size_t(ctx.tiles_y) * ctx.tiles_z;
    start.assign(tiles + 1, 0);
    auto each = [&](auto&& visit) {
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
            const ColumnBounds b =
                triangle_columns(&gv.fixed[3 * std::size_t(mesh.indices[3 * t])],
                                 &gv.fixed[3 * std::size_t(mesh.indices[3 * t + 1])],
                                 &gv.fixed[3 * std::size_t(mesh.indices[3 * t + 2])], ctx.ny, ctx.nz);
            if (b.y0 > b.y1 || b.z0 > b.z1) continue;
            for (int tz = b.z0 / kTile; tz <= b.z1 / kTile; ++tz)
                for (int ty = b.y0 / kTile; ty <= b.y1 / kTile; ++ty)
                    visit(std::size_t(tz) * ctx.tiles_y + ty, static_cast<std::uint32_t>(t));
        }
    };
    each([&](std::size_t tile, std::uint32_t) { ++start[tile + 1]; });
    for (std::size_t i = 0; i < tiles; ++i) start[i + 1] += start[i];
    list.resize(start[tiles]);
    std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
    each([&](std::size_t tile, std::uint32_t t) { list[cursor[tile]++] = t; });
}

// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5), as barycentric
// weights of a, b, c.
std::array<double, 3> closest_weights(const double* p, const double* a, const double* b, const double* c) {
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; ++k) ab[k] = b[k] - a[k], ac[k] = c[k] - a[k], ap[k] = p[k] - a[k];
    auto dot3 = [](const double* u, const double* v) { return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]; };
    const double d1 = dot3(ab, ap), d2 = dot3(ac, ap);
    if (d1 <= 0 && d2 <= 0) return {1, 0, 0};
    for (int k = 0; k < 3; ++k) bp[k] = p[k] - b[k];
    const double d3 = dot3(ab, bp), d4 = dot3(ac, bp);
    if (d3 >= 0 && d4 <= d3) return {0, 1, 0};
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) {
        const double v = d1 / (d1 - d3);
        return {1 - v, v, 0};
    }
    for (int k = 0; k < 3; ++k) cp[k] = p[k] - c[k];
    const double d5 = dot3(ab, cp), d6 = dot3(ac, cp);
    if (d6 >= 0 && d5 <= d6) return {0, 0, 1};
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) {
        const double w = d2 / (d2 - d6);
        return {1 - w, 0, w};
    }
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return {0, 1 - w, w};
    }
    const double denom = va + vb + vc;
    if (!(std::abs(denom) > 0)) return {1, 0, 0};  // no area: a's colour
    const double v = vb / denom, w = vc / denom;
    return {1 - v - w, v, w};
}

// Inside voxels within kBand of the surface: exact closest triangle (lowest number on ties), its colour
// interpolated there. Each task owns kColourSlab voxel layers and visits the triangles whose dilated
// bounds meet them in triangle order, so the result does not depend on scheduling.
void seed_colours(const ColoredMesh& mesh, const GridVertices& gv, SolidVoxels& out,
                  std::vector<float>& best) {
    const VoxelGridShape& s = out.shape;
    const int slabs = (s.nz + kColourSlab - 1) / kColourSlab;
    struct Box {
        int lo[3], hi[3];
    };
    auto dilated = [&](std::size_t t) {
        Box box;
        const int n[3] = {s.nx, s.ny, s.nz};
        for (int k = 0; k < 3; ++k) {
            double lo = gv.g[3 * std::size_t(mesh.indices[3 * t]) + k], hi = lo;
            for (int c = 1; c < 3; ++c) {
                const double v = gv.g[3 * std::size_t(mesh.indices[3 * t + c]) + k];
                lo = std::min(lo, v), hi = std::max(hi, v);
            }
            box.lo[k] = static_cast<int>(std::max(0.0, std::ceil(lo - kBand)));
            box.hi[k] = static_cast<int>(std::min(n[k] - 1.0, std::floor(hi + kBand)));
        }
        return box;
    };
    std::vector<std::uint32_t> start(std::size_t(slabs) + 1, 0), list;
    for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
        const Box b = dilated(t);
        if (b.lo[2] > b.hi[2]) continue;
        for (int z = b.lo[2] / kColourSlab; z <= b.hi[2] / kColourSlab; ++z) ++start[std::size_t(z) + 1];
    }
    for (int i = 0; i < slabs; ++i) start[std::size_t(i) + 1] += start[std::size_t(i)];
    list.resize(start.back());
    {
        std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
        for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
            const Box b = dilated(t);
            if (b.lo[2] > b.hi[2]) continue;
            for (int z = b.lo[2] / kColourSlab; z <= b.hi[2] / kColourSlab; ++z)
                list[cursor[std::size_t(z)]++] = static_cast<std::uint32_t>(t);
        }
    }
    tbb::parallel_for(0, slabs, [&](int slab) {
        const int z_begin = slab * kColourSlab, z_end = std::min(s.nz, z_begin + kColourSlab);
        for (std::uint32_t k = start[std::size_t(slab)]; k < start[std::size_t(slab) + 1]; ++k) {
            const std::uint32_t t = list[k];
            const std::uint32_t vi[3] = {mesh.indices[3 * std::size_t(t)],
                                         mesh.indices[3 * std::size_t(t) + 1],
                                         mesh.indices[3 * std::size_t(t) + 2]};
            const double* a = &gv.g[3 * std::size_t(vi[0])];
            const double* b = &gv.g[3 * std::size_t(vi[1])];
            const double* c = &gv.g[3 * std::size_t(vi[2])];
            // Plane test first: large triangles have large boxes, most of them far from the plane.
            double n[3] = {(b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]),
                           (b[2] - a[2]) * (c[0] - a[0]) - (b[0] - a[0]) * (c[2] - a[2]),
                           (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])};
            const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            const bool flat = len > 0;
            if (flat)
                for (double& v : n) v /= len;
            const Box box = dilated(t);
            for (int iz = std::max(box.lo[2], z_begin); iz <= std::min(box.hi[2], z_end - 1); ++iz)
                for (int iy = box.lo[1]; iy <= box.hi[1]; ++iy)
                    for (int ix = box.lo[0]; ix <= box.hi[0]; ++ix) {
                        const std::size_t v = s.index(ix, iy, iz);
                        if (!out.inside[v]) continue;
                        const double p[3] = {double(ix), double(iy), double(iz)};
                        if (flat && std::abs((p[0] - a[0]) * n[0] + (p[1] - a[1]) * n[1] +
                                             (p[2] - a[2]) * n[2]) > kBand)
                            continue;
                        const auto w = closest_weights(p, a, b, c);
                        double d2 = 0;
                        for (int q = 0; q < 3; ++q) {
                            const double d = w[0] * a[q] + w[1] * b[q] + w[2] * c[q] - p[q];
                            d2 += d * d;
                        }
                        if (d2 > kBand * kBand || !(static_cast<float>(d2) < best[v])) continue;
                        best[v] = static_cast<float>(d2);
                        float rgb[3];
                        for (int q = 0; q < 3; ++q)
                            rgb[q] = std::clamp(static_cast<float>(w[0] * mesh.colors[3 * vi[0] + q] +
                                                                   w[1] * mesh.colors[3 * vi[1] + q] +
                                                                   w[2] * mesh.colors[3 * vi[2] + q]),
                                                0.0f, 1.0f);
                        out.r[v] = rgb[0], out.g[v] = rgb[1], out.b[v] = rgb[2];
                    }
        }
    });
}

// One line of the exact squared Euclidean distance transform with nearest-site tracking (Felzenszwalb &
// Huttenlocher, "Distance Transforms of Sampled Functions"): f and site are read at stride `step` and
// overwritten with min_q (i - q)^2 + f(q) and the site of the minimising q. Ties keep the lower q.
struct EnvelopeScratch {
    std::vector<int> v;
    std::vector<float> z, f;
    std::vector<std::uint32_t> site;
    explicit EnvelopeScratch(int n)
        : v(std::size_t(n)), z(std::size_t(n) + 1), f(std::size_t(n)), site(std::size_t(n)) {}
};

void envelope_line(float* f_line, std::uint32_t* site_line, std::size_t step, int n, EnvelopeScratch& sc) {
    int k = -1;
    for (int q = 0; q < n; ++q) {
        sc.f[std::size_t(q)] = f_line[std::size_t(q) * step];
        sc.site[std::size_t(q)] = site_line[std::size_t(q) * step];
        if (sc.f[std::size_t(q)] == kFar) continue;
        float zq = -kFar;
        while (k >= 0) {
            const int p = sc.v[std::size_t(k)];
            zq = ((sc.f[std::size_t(q)] + float(q) * float(q)) -
                  (sc.f[std::size_t(p)] + float(p) * float(p))) /
                 (2.0f * float(q - p));
            if (zq > sc.z[std::size_t(k)]) break;
            --k;
        }
        ++k;
        sc.v[std::size_t(k)] = q;
        sc.z[std::size_t(k)] = k == 0 ? -kFar : zq;
        sc.z[std::size_t(k) + 1] = kFar;
    }
    if (k < 0) return;  // no site on this line: it stays far
    int j = 0;
    for (int q = 0; q < n; ++q) {
        while (sc.z[std::size_t(j) + 1] < float(q)) ++j;
        const int p = sc.v[std::size_t(j)];
        f_line[std::size_t(q) * step] = float(q - p) * float(q - p) + sc.f[std::size_t(p)];
        site_line[std::size_t(q) * step] = sc.site[std::size_t(p)];
    }
}

// Deeper inside voxels take the colour of the nearest seed voxel.
void spread_colours(SolidVoxels& out, std::vector<float>& dist) {
    const VoxelGridShape& s = out.shape;
    std::vector<std::uint32_t> site(s.count());
    for (std::size_t v = 0; v < s.count(); ++v) {
        dist[v] = dist[v] == kFar ? kFar : 0.0f;
        site[v] = static_cast<std::uint32_t>(v);
    }
    const int n[3] = {s.nx, s.ny, s.nz};
    const std::size_t stride[3] = {1, std::size_t(s.nx), std::size_t(s.nx) * s.ny};
    for (int axis = 0; axis < 3; ++axis) {
        const int u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;  // the two other axes
        tbb::parallel_for(tbb::blocked_range<int>(0, n[w]), [&](const tbb::blocked_range<int>& r) {
            EnvelopeScratch sc(n[axis]);
            for (int j = r.begin(); j < r.end(); ++j)
                for (int i = 0; i < n[u]; ++i) {
                    const std::size_t base = std::size_t(i) * stride[u] + std::size_t(j) * stride[w];
                    envelope_line(dist.data() + base, site.data() + base, stride[axis], n[axis], sc);
                }
        });
    }
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, s.count()), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t v = r.begin(); v < r.end(); ++v) {
                if (!out.inside[v]) continue;
                if (dist[v] == kFar) {  // no seed anywhere: cannot happen for a closed mesh, but stay defined
                    out.r[v] = out.g[v] = out.b[v] = 1.0f;
                    continue;
                }
                if (site[v] == v) continue;  // a seed keeps its own colour
                out.r[v] = out.r[site[v]], out.g[v] = out.g[site[v]], out.b[v] = out.b[site[v]];
            }
        });
}

}  // namespace

std::size_t SolidVoxels::inside_count() const {
    std::size_t n = 0;
    for (std::uint8_t v : inside) n += v;
    return n;
}

SolidVoxels voxelize(const ColoredMesh& mesh, int resolution, int padding) {
    validate(mesh, resolution, padding);
    require_closed(mesh);
    SolidVoxels out;
    out.shape = grid_shape(mesh, resolution, padding);
    const VoxelGridShape& s = out.shape;
    const GridVertices gv = to_grid(mesh, s);

    VoxelizeColumnsContext ctx;
    ctx.nx = s.nx, ctx.ny = s.ny, ctx.nz = s.nz;
    ctx.tile = kTile;
    ctx.tiles_y = (s.ny + kTile - 1) / kTile;
    ctx.tiles_z = (s.nz + kTile - 1) / kTile;
    std::vector<std::uint32_t> tile_start, tile_triangles;
    bin_tiles(mesh, gv, ctx, tile_start, tile_triangles);
    out.inside.resize(s.count());
    ctx.fixed = gv.fixed;
    ctx.indices = mesh.indices;
    ctx.tile_start = tile_start;
    ctx.tile_triangles = tile_triangles;
    ctx.inside = out.inside;
    tbb::parallel_for(0, ctx.tiles_z, [&](int tz) { voxelize_columns(tz, ctx); });

    out.r.assign(s.count(), 0.0f);
    out.g.assign(s.count(), 0.0f);
    out.b.assign(s.count(), 0.0f);
    if (mesh.colors.empty()) {
        for (std::size_t v = 0; v < s.count(); ++v)
            if (out.inside[v]) out.r[v] = out.g[v] = out.b[v] = 1.0f;
        return out;
    }
    std::vector<float> best(s.count(), kFar);
    seed_colours(mesh, gv, out, best);
    spread_colours(out, best);
    return out;
}

}  // namespace rivulet
