#include "runtime/lib/mesh_decomposition.h"

#include <fmt/format.h>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <unordered_map>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/slices_jobs.h"
#include "systems/particles/particle_set.h"
#include "systems/particles/radius_estimate.h"
#include "systems/slices/slices_extractor.h"

namespace rivulet {
namespace {

std::uint32_t block_along(const SliceGrid& g, std::uint32_t block, int axis) {
    if (axis == 0) return block % g.bx;
    if (axis == 1) return (block / g.bx) % g.by;
    return block / (g.bx * g.by);
}

// Slab cuts (pieces + 1 block indices along `axis`) with about equal particles per slab, each at least
// one block wide.
std::vector<std::uint32_t> plan_slabs(std::span<const std::uint64_t> particles_per_block, int pieces) {
    const auto blocks = static_cast<std::uint32_t>(particles_per_block.size());
    std::uint64_t total = 0;
    for (std::uint64_t c : particles_per_block) total += c;
    std::vector<std::uint32_t> cuts(static_cast<std::size_t>(pieces) + 1, 0);
    cuts.back() = blocks;
    std::uint64_t below = 0;  // particles in blocks [0, b)
    std::uint32_t b = 0;
    for (int r = 1; r < pieces; ++r) {
        const std::uint64_t target =
            total * static_cast<std::uint64_t>(r) / static_cast<std::uint64_t>(pieces);
        while (b < blocks && below < target) below += particles_per_block[b++];
        const std::uint32_t lowest = cuts[std::size_t(r) - 1] + 1;
        const std::uint32_t highest = blocks - static_cast<std::uint32_t>(pieces - r);
        cuts[std::size_t(r)] = std::clamp(b, lowest, highest);
    }
    return cuts;
}

struct VertexKey {
    std::array<std::uint32_t, 6> bits;
    bool operator==(const VertexKey&) const = default;
};

struct VertexKeyHash {
    std::size_t operator()(const VertexKey& k) const {
        std::uint64_t h = 0x9e3779b97f4a7c15ull;
        for (std::uint32_t b : k.bits) h = (h ^ b) * 0x100000001b3ull;
        return static_cast<std::size_t>(h ^ (h >> 29));
    }
};

}  // namespace

MeshPiece extract_mesh_piece(const ParticleCloud& cloud, const MeshSettings& request, int piece, int pieces) {
    if (request.method != "slices")
        throw std::invalid_argument(
            "a frame is split into pieces by marching slices' blocks: use --method slices");
    if (pieces < 1 || piece < 0 || piece >= pieces)
        throw std::invalid_argument(fmt::format("piece {} of {} does not exist", piece, pieces));
    const std::size_t n = cloud.x.size();
    if (n == 0) throw std::invalid_argument("no particles to mesh");
    const ConstPositions whole{cloud.x, cloud.y, cloud.z};
    SlicesSettings settings = request.slices;
    settings.radius = request.radius > 0 ? request.radius : estimate_particle_radius(whole);
    if (!(settings.radius > 0))
        throw std::invalid_argument(
            "cannot estimate a particle radius (all particles coincide): pass --radius");
    SlicesExtractor slices(settings, n);
    slices.fix_frame(whole);
    const SliceGrid& grid = slices.grid();

    MeshPiece out;
    const std::uint32_t nb[3] = {grid.bx, grid.by, grid.bz};
    out.axis = nb[1] > nb[out.axis] ? 1 : out.axis;
    out.axis = nb[2] > nb[out.axis] ? 2 : out.axis;
    const int axis = out.axis;
    if (nb[axis] < static_cast<std::uint32_t>(pieces))
        throw std::invalid_argument(fmt::format(
            "the frame has {} blocks along its longest axis, fewer than the {} pieces asked for: use fewer "
            "ranks or a smaller --block",
            nb[axis], pieces));
    const std::span<const float> along = axis == 0   ? std::span<const float>(cloud.x)
                                         : axis == 1 ? std::span<const float>(cloud.y)
                                                     : std::span<const float>(cloud.z);
    const float origin = axis == 0 ? grid.ox : axis == 1 ? grid.oy : grid.oz;
    std::vector<std::int32_t> cells(n);
    std::vector<std::uint64_t> per_block(nb[axis], 0);
    for (std::size_t i = 0; i < n; ++i) {
        cells[i] = SliceGrid::cell(along[i], origin, grid.inv_voxel);
        ++per_block[std::min<std::uint32_t>(static_cast<std::uint32_t>(cells[i]) / grid.n, nb[axis] - 1)];
    }
    const std::vector<std::uint32_t> cuts = plan_slabs(per_block, pieces);
    out.first_block = cuts[std::size_t(piece)], out.end_block = cuts[std::size_t(piece) + 1];
    out.voxel = grid.voxel;
    out.face_lo = origin + grid.voxel * static_cast<float>(out.first_block * grid.n);
    out.face_hi = origin + grid.voxel * static_cast<float>(out.end_block * grid.n);

    // Ghosts: the block beyond each side of the slab holds every particle it would in the whole frame,
    // so the slab's blocks and their neighbours (which own vertices on the seams and add to the normals
    // there) sweep as they do there. Blocks further out may miss particles; nothing of theirs is kept.
    const auto block_cubes = static_cast<std::int64_t>(grid.n);
    const std::int64_t margin = block_cubes + grid.reach + 2;
    const std::int64_t keep_lo = std::int64_t(out.first_block) * block_cubes - margin;
    const std::int64_t keep_hi = std::int64_t(out.end_block) * block_cubes + margin;
    ParticleSet part(n);
    for (std::size_t i = 0; i < n; ++i)
        if (cells[i] >= keep_lo && cells[i] < keep_hi)
            part.push(cloud.x[i], cloud.y[i], cloud.z[i], 0, 0, 0, static_cast<std::uint32_t>(i));
    out.particles = part.size();
    if (part.size() == 0) return out;

    SurfaceMesh mesh;
    FrameGraph graph;
    add_slices_jobs(
        graph, slices, [&part] { return part.positions(); }, [&mesh]() -> SurfaceMesh& { return mesh; });
    graph.run();
    out.extract_ms = graph.last_run_ms();

    std::vector<std::uint32_t> remap(mesh.vertex_count, SlicesExtractor::kMissingVertex);
    std::uint64_t kept = 0;
    for (std::uint32_t item = 0; item < slices.blocks(); ++item) {
        const std::uint32_t b = block_along(grid, slices.block_id(item), axis);
        if (b >= out.first_block && b < out.end_block) kept += slices.block_triangle_count(item);
    }
    out.indices.reserve(kept * 3);
    out.vertices.reserve(std::min<std::uint64_t>(kept * 3, mesh.vertex_count) * 6);
    for (std::uint32_t item = 0; item < slices.blocks(); ++item) {
        const std::uint32_t b = block_along(grid, slices.block_id(item), axis);
        if (b < out.first_block || b >= out.end_block) continue;
        const std::uint64_t first = slices.block_triangle_offset(item) * 3;
        const std::uint64_t end = first + std::uint64_t(slices.block_triangle_count(item)) * 3;
        for (std::uint64_t c = first; c < end; ++c) {
            const std::uint32_t v = mesh.indices[c];
            if (v == SlicesExtractor::kMissingVertex)
                throw std::logic_error("mesh piece: a slab block refers to a vertex beyond the ghost margin");
            if (remap[v] == SlicesExtractor::kMissingVertex) {
                remap[v] = static_cast<std::uint32_t>(out.vertices.size() / 6);
                out.vertices.insert(out.vertices.end(), mesh.vertices6.data() + std::size_t(v) * 6,
                                    mesh.vertices6.data() + std::size_t(v) * 6 + 6);
            }
            out.indices.push_back(remap[v]);
        }
    }
    return out;
}

TriangleMesh weld_mesh_pieces(std::span<const MeshPiece> pieces) {
    TriangleMesh mesh;
    std::unordered_map<VertexKey, std::uint32_t, VertexKeyHash> index;
    std::vector<std::uint32_t> remap;
    std::size_t floats = 0, indices = 0;
    for (const MeshPiece& p : pieces) floats += p.vertices.size(), indices += p.indices.size();
    mesh.vertices.reserve(floats), mesh.indices.reserve(indices);
    for (const MeshPiece& p : pieces) {
        const std::size_t vertices = p.vertices.size() / 6;
        remap.assign(vertices, 0);
        for (std::size_t v = 0; v < vertices; ++v) {
            const auto next = static_cast<std::uint32_t>(mesh.vertex_count());
            const float along = p.vertices[v * 6 + std::size_t(p.axis)];
            const bool on_seam =
                std::abs(along - p.face_lo) <= p.voxel || std::abs(along - p.face_hi) <= p.voxel;
            remap[v] = next;
            if (on_seam) {
                VertexKey key;
                for (std::size_t c = 0; c < 6; ++c)
                    key.bits[c] = std::bit_cast<std::uint32_t>(p.vertices[v * 6 + c]);
                remap[v] = index.try_emplace(key, next).first->second;
            }
            if (remap[v] == next)  // a vertex no earlier piece had
                mesh.vertices.insert(mesh.vertices.end(), p.vertices.begin() + std::ptrdiff_t(v * 6),
                                     p.vertices.begin() + std::ptrdiff_t(v * 6 + 6));
        }
        for (std::uint32_t i : p.indices) mesh.indices.push_back(remap[i]);
    }
    return mesh;
}

}  // namespace rivulet
