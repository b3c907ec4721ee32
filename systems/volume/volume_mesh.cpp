#include "systems/volume/volume_mesh.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "jobs/volume_marching_cubes.h"

namespace rivulet {
namespace {

// What one brick's kernel produced, kept until the weld has looked up its neighbours' edges.
struct BrickPart {
    std::vector<float> vertices;              // 6 per vertex
    std::vector<std::uint16_t> foreign_edge;  // per vertex past `owned`: its brick_edge_slot
    std::vector<std::uint16_t> edge_vertex;   // kBrickEdgeSlots, or empty without vertices
    std::vector<std::uint16_t> triangles;
    std::uint32_t owned = 0;
    // Where each foreign vertex ends up: vertex foreign_at of slot foreign_slot's share of the mesh. A
    // vertex whose owner has no vertex on its edge (the two copies of a shared sample disagree, which a
    // valid volume rules out) stays with this brick, after its owned ones: a crack rather than a bad index.
    std::vector<std::uint32_t> foreign_slot;
    std::vector<std::uint16_t> foreign_at;
    std::uint32_t kept = 0;  // vertices this brick puts in the mesh: owned, then the ones kept as above
    std::uint64_t vertex_offset = 0, index_offset = 0;
};

// The kernel's capacities, per thread (not per range: ranges can be one brick each) and not zeroed (the
// kernel writes before it reads).
struct KernelScratch {
    std::unique_ptr<float[]> vertices =
        std::make_unique_for_overwrite<float[]>(6 * std::size_t(kBrickMaxVertices));
    std::unique_ptr<std::uint16_t[]> vertex_edge =
        std::make_unique_for_overwrite<std::uint16_t[]>(kBrickMaxVertices);
    std::unique_ptr<std::uint16_t[]> edge_vertex =
        std::make_unique_for_overwrite<std::uint16_t[]>(kBrickEdgeSlots);
    std::unique_ptr<std::uint16_t[]> triangles =
        std::make_unique_for_overwrite<std::uint16_t[]>(3 * std::size_t(kBrickMaxTriangles));
    BrickMeshOut out() const {
        return {{vertices.get(), 6 * std::size_t(kBrickMaxVertices)},
                {vertex_edge.get(), kBrickMaxVertices},
                {edge_vertex.get(), kBrickEdgeSlots},
                {triangles.get(), 3 * std::size_t(kBrickMaxTriangles)}};
    }
};

void validate(const DensityVolumeView& v) {
    if (!(v.iso > 0) || !std::isfinite(v.iso))
        throw std::invalid_argument("density volume mesh: iso must be positive and finite");
    const std::uint32_t stored = v.stored(), bricks = v.grid.bricks();
    if (v.brick_slot.size() != bricks || v.slot_brick.size() != stored || v.slot_max.size() != stored ||
        v.atlas.size() < atlas_samples(atlas_layers(stored)))
        throw std::invalid_argument("density volume mesh: the view's spans do not match its grid");
    for (const std::int32_t s : v.brick_slot)
        if (s < -1 || s >= std::int64_t(stored))
            throw std::invalid_argument("density volume mesh: a brick names a slot that is not stored");
    for (std::uint32_t s = 0; s < stored; ++s)
        if (v.slot_brick[s] >= bricks || v.brick_slot[v.slot_brick[s]] != std::int32_t(s))
            throw std::invalid_argument("density volume mesh: slot_brick and brick_slot disagree");
}

}  // namespace

TriangleMesh mesh_density_volume(const DensityVolumeView& v) {
    validate(v);
    const std::uint32_t stored = v.stored();
    const DensityGrid& g = v.grid;
    std::vector<BrickPart> parts(stored);

    // Each brick into its own part: which thread runs it changes nothing.
    tbb::enumerable_thread_specific<KernelScratch> scratch;
    tbb::parallel_for(tbb::blocked_range<std::uint32_t>(0, stored),
                      [&](const tbb::blocked_range<std::uint32_t>& r) {
                          const BrickMeshOut out = scratch.local().out();
                          for (std::uint32_t slot = r.begin(); slot != r.end(); ++slot) {
                              const BrickMeshStats st = march_brick(v, slot, out);
                              if (st.vertices == 0) continue;
                              BrickPart& p = parts[slot];
                              p.owned = st.owned;
                              p.vertices.assign(out.vertices.begin(),
                                                out.vertices.begin() + 6 * std::ptrdiff_t(st.vertices));
                              p.foreign_edge.assign(out.vertex_edge.begin() + st.owned,
                                                    out.vertex_edge.begin() + st.vertices);
                              p.edge_vertex.assign(out.edge_vertex.begin(), out.edge_vertex.end());
                              p.triangles.assign(out.triangles.begin(),
                                                 out.triangles.begin() + 3 * std::ptrdiff_t(st.triangles));
                          }
                      });

    // The weld: each foreign vertex to its owner's copy (parts are read-only here but for their own).
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, stored), [&](const tbb::blocked_range<std::uint32_t>& r) {
            for (std::uint32_t slot = r.begin(); slot != r.end(); ++slot) {
                BrickPart& p = parts[slot];
                const std::uint32_t id = v.slot_brick[slot];
                const std::uint32_t brick[3] = {id % g.bx, (id / g.bx) % g.by, id / (g.bx * g.by)};
                const std::size_t foreign = p.foreign_edge.size();
                p.foreign_slot.resize(foreign);
                p.foreign_at.resize(foreign);
                p.kept = p.owned;
                for (std::size_t f = 0; f < foreign; ++f) {
                    const std::uint32_t e = p.foreign_edge[f], axis = e % 3, at = e / 3;
                    const std::uint32_t local[3] = {at % kBrickEdge, (at / kBrickEdge) % kBrickEdge,
                                                    at / (kBrickEdge * kBrickEdge)};
                    const BrickEdgeRef owner = brick_edge_owner(g, brick[0] * kBrickCells + local[0],
                                                                brick[1] * kBrickCells + local[1],
                                                                brick[2] * kBrickCells + local[2], axis);
                    const std::int32_t os = v.brick_slot[owner.brick];
                    const BrickPart* o = os >= 0 ? &parts[static_cast<std::uint32_t>(os)] : nullptr;
                    if (o && !o->edge_vertex.empty() && o->edge_vertex[owner.edge] != kNoVertex) {
                        p.foreign_slot[f] = static_cast<std::uint32_t>(os);
                        p.foreign_at[f] = o->edge_vertex[owner.edge];
                    } else {
                        p.foreign_slot[f] = slot;
                        p.foreign_at[f] = static_cast<std::uint16_t>(p.kept++);
                    }
                }
            }
        });

    std::uint64_t vertices = 0, indices = 0;
    for (BrickPart& p : parts) {
        p.vertex_offset = vertices;
        p.index_offset = indices;
        vertices += p.kept;
        indices += p.triangles.size();
    }
    constexpr std::uint64_t kMaxIndex = std::numeric_limits<std::uint32_t>::max();
    if (vertices > kMaxIndex || indices > kMaxIndex)
        throw std::length_error("density volume mesh: more than 2^32 vertices or indices");

    TriangleMesh mesh;
    mesh.vertices.resize(6 * vertices);
    mesh.indices.resize(indices);
    tbb::parallel_for(
        tbb::blocked_range<std::uint32_t>(0, stored), [&](const tbb::blocked_range<std::uint32_t>& r) {
            std::vector<std::uint32_t> foreign_mesh;
            for (std::uint32_t slot = r.begin(); slot != r.end(); ++slot) {
                const BrickPart& p = parts[slot];
                if (p.vertices.empty()) continue;
                float* dst = mesh.vertices.data() + 6 * p.vertex_offset;
                std::memcpy(dst, p.vertices.data(), 6 * std::size_t(p.owned) * sizeof(float));
                const std::size_t foreign = p.foreign_edge.size();
                foreign_mesh.resize(foreign);
                for (std::size_t f = 0; f < foreign; ++f) {
                    const std::uint32_t at = p.foreign_at[f];
                    foreign_mesh[f] = static_cast<std::uint32_t>(parts[p.foreign_slot[f]].vertex_offset + at);
                    if (p.foreign_slot[f] == slot)
                        std::memcpy(dst + 6 * std::size_t(at), p.vertices.data() + 6 * (p.owned + f),
                                    6 * sizeof(float));
                }
                const auto base = static_cast<std::uint32_t>(p.vertex_offset);
                std::uint32_t* out = mesh.indices.data() + p.index_offset;
                for (std::size_t q = 0; q < p.triangles.size(); ++q) {
                    const std::uint32_t local = p.triangles[q];
                    out[q] = local < p.owned ? base + local : foreign_mesh[local - p.owned];
                }
            }
        });
    return mesh;
}

}  // namespace rivulet
