// One frame meshed in pieces (runtime/lib/mesh_decomposition.h): the welded pieces are the whole frame's
// marching-slices mesh as a set of triangles (positions and normals, bit for bit), watertight across the
// slab seams, for 2 and 3 pieces, on a jittered fluid block with droplets and on a fountain's streams.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <vector>

#include "jobs/counter_rng.h"
#include "runtime/lib/mesh_decomposition.h"
#include "runtime/lib/scene_simulation.h"
#include "support/test_support.h"
#include "systems/particles/radius_estimate.h"
#include "systems/scenes/scene.h"

namespace rivulet {
namespace {

using Triangle = std::array<std::uint32_t, 18>;  // three vertices: position and normal bits

std::vector<Triangle> triangle_set(std::span<const float> vertices, std::span<const std::uint32_t> indices) {
    std::vector<Triangle> out(indices.size() / 3);
    for (std::size_t t = 0; t < out.size(); ++t)
        for (std::size_t c = 0; c < 3; ++c)
            for (std::size_t f = 0; f < 6; ++f)
                out[t][c * 6 + f] = std::bit_cast<std::uint32_t>(vertices[indices[t * 3 + c] * 6 + f]);
    std::sort(out.begin(), out.end());
    return out;
}

// A tank's block of fluid, jittered off its lattice as a simulation leaves it, with a spray of droplets
// over it: seams cut through the bulk, its free surface and lone drops.
ParticleCloud splash(float spacing) {
    ParticleCloud c;
    std::uint64_t id = 0;
    for (int i = 0; i < 48; ++i)
        for (int j = 0; j < 14; ++j)
            for (int k = 0; k < 10; ++k, ++id) {
                const float jitter = 0.3f * spacing;
                c.x.push_back(spacing * float(i) + jitter * (counter_uniform(7, 0, id, 0) - 0.5f));
                c.y.push_back(spacing * float(j) + jitter * (counter_uniform(7, 0, id, 1) - 0.5f));
                c.z.push_back(spacing * float(k) + jitter * (counter_uniform(7, 0, id, 2) - 0.5f));
            }
    for (int d = 0; d < 300; ++d, ++id) {
        c.x.push_back(48 * spacing * counter_uniform(7, 1, id, 0));
        c.y.push_back(spacing * (16 + 12 * counter_uniform(7, 1, id, 1)));
        c.z.push_back(10 * spacing * counter_uniform(7, 1, id, 2));
    }
    return c;
}

// `thin_slabs`: the slabs are narrow against the ghost margin's two blocks, yet no piece needs them all.
void expect_pieces_make_the_whole(const ParticleCloud& cloud, const MeshSettings& request, bool thin_slabs) {
    const MeshResult whole = extract_mesh(cloud, request);
    ASSERT_GT(whole.mesh.triangle_count(), 1000u);
    const std::vector<Triangle> want = triangle_set(whole.mesh.vertices, whole.mesh.indices);
    std::vector<std::array<std::uint32_t, 6>> keys(whole.mesh.vertex_count());
    for (std::size_t v = 0; v < keys.size(); ++v)
        for (std::size_t f = 0; f < 6; ++f)
            keys[v][f] = std::bit_cast<std::uint32_t>(whole.mesh.vertices[v * 6 + f]);
    std::sort(keys.begin(), keys.end());
    const auto distinct_vertices =
        static_cast<std::size_t>(std::unique(keys.begin(), keys.end()) - keys.begin());
    const std::size_t open_whole =
        test::count_open_edges(test::strided_positions(whole.mesh.vertices, 6), whole.mesh.indices);
    for (int pieces : {2, 3}) {
        std::vector<MeshPiece> parts;
        for (int r = 0; r < pieces; ++r) parts.push_back(extract_mesh_piece(cloud, request, r, pieces));
        for (int r = 0; r < pieces; ++r) {
            EXPECT_LT(parts[r].first_block, parts[r].end_block);
            if (r > 0) {
                EXPECT_EQ(parts[r].first_block, parts[r - 1].end_block);
            }
            if (thin_slabs) {
                EXPECT_LT(parts[r].particles, cloud.x.size()) << "piece " << r << " holds every particle";
            }
            EXPECT_GT(parts[r].indices.size(), 0u) << "piece " << r << " is empty";
        }
        const TriangleMesh welded = weld_mesh_pieces(parts);
        // Seam vertices merge where position and normal are the same bits (which may also merge two
        // vertices of the whole mesh that happen to coincide there).
        EXPECT_LE(welded.vertex_count(), whole.mesh.vertex_count()) << pieces << " pieces";
        EXPECT_GE(welded.vertex_count(), distinct_vertices) << pieces << " pieces";
        EXPECT_TRUE(triangle_set(welded.vertices, welded.indices) == want) << pieces << " pieces";
        EXPECT_EQ(test::count_open_edges(test::strided_positions(welded.vertices, 6), welded.indices),
                  open_whole)
            << pieces << " pieces";
    }
    EXPECT_EQ(open_whole, 0u);
}

MeshSettings slices_request(float radius, std::uint32_t block_cubes) {
    MeshSettings r;
    r.method = "slices";
    r.radius = radius;
    r.slices.block_cubes = block_cubes;
    return r;
}

TEST(MeshDecomposition, PiecesOfASplashAreItsMeshAsASetOfTrianglesAndWatertight) {
    const float spacing = 0.01f;
    // Blocks of 8 cubes: many seams, each crossing the bulk and the spray.
    expect_pieces_make_the_whole(splash(spacing), slices_request(0.5f * spacing, 8), true);
    // The radius a user who reads it as the spacing would give, and the default block.
    expect_pieces_make_the_whole(splash(spacing), slices_request(spacing, SlicesSettings{}.block_cubes),
                                 false);
}

TEST(MeshDecomposition, PiecesOfAFountainsStreamsAreItsMesh) {
    SceneDesc scene = make_builtin_scene("fountain");
    SceneSimulation sim(scene);
    sim.step_serial(scene.warmup_frames);
    const ConstPositions p = sim.particles().positions();
    ParticleCloud cloud;
    cloud.x.assign(p.x.begin(), p.x.end()), cloud.y.assign(p.y.begin(), p.y.end());
    cloud.z.assign(p.z.begin(), p.z.end());
    // Twice the estimated radius: a coarser mesh, as quick to check and with the same seams.
    expect_pieces_make_the_whole(cloud, slices_request(2 * estimate_particle_radius(p), 12), false);
}

TEST(MeshDecomposition, RefusesWhatItCannotSplit) {
    const ParticleCloud cloud = splash(0.01f);
    MeshSettings scan = slices_request(0.005f, 40);
    scan.method = "scan";
    EXPECT_THROW(extract_mesh_piece(cloud, scan, 0, 2), std::invalid_argument);
    MeshSettings stretched = slices_request(0.005f, 40);
    stretched.slices.anisotropy = 3;
    EXPECT_THROW(extract_mesh_piece(cloud, stretched, 0, 2), std::invalid_argument);
    // The block along the longest axis are fewer than the pieces.
    EXPECT_THROW(extract_mesh_piece(cloud, slices_request(0.005f, 128), 0, 64), std::invalid_argument);
    EXPECT_THROW(extract_mesh_piece(cloud, slices_request(0.005f, 40), 2, 2), std::invalid_argument);
}

}  // namespace
}  // namespace rivulet
