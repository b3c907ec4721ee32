#pragma once
// Surface-following marching cubes inside one block ("marching slices", Rosenberg & Birdwell 2008,
// Janisz §3.2.3). The block's n^3 cubes form n slabs between n+1 slices (planes of constant z). Each slab
// has a todo list of queued cubes, kept as rows of bits (bit_rows.h). The sweep always works on the
// lowest slab whose list is not empty: it floods it, round by round taking its queued cubes, computing
// their missing corners and queueing every neighbour across a face the surface crosses (in the slabs
// above and below too), all as word operations on bit rows; then it creates the vertices on the crossed
// edges of the cubes it visited and writes their triangles, row by row. A cube is queued at most once
// per block. Corner values live in slice caches that are taken from a small pool when a slab first
// needs them and given back as soon as the sweep has moved above them (recomputed, identically, should
// the surface lead back down).
//
// Seeds, all found before the sweep:
//  1. the O(P) heuristic: from the corner nearest each particle's centre, walk along the column to the
//     first outside corner, down from the block's lower half and up from its upper half (the nearer
//     face); the cubes around that crossing are seeds (a per-column memo of the inside run already
//     walked keeps this linear). Particles above the block start at its top slice. When the
//     nearest corner is outside the fluid (coarse voxels, thin parts), the walk starts from the first
//     inside corner of the cube holding the centre instead.
//  2. completeness: the heuristic finds a piece of surface near each particle, but not every piece that
//     lies in this block (e.g. the top of a body whose bottom is in a lower block, or a piece the walk
//     never meets); so every face of the block that can carry surface (not on the grid's outer
//     boundary) is scanned and every face cell the surface crosses seeds its cube. With (1) this finds
//     every surface piece that meets a block face or encloses a particle centre inside the block. The
//     sweep follows the surface both up and down, so seeds need not be local minima.
//     A face between two non-empty blocks is scanned by whichever of them gets to it first, which
//     publishes its bits for the other (SharedFace).
//
// Vertices are shared within the block through an edge table (one vertex per crossed edge, created once
// per block); those on block borders are also listed with their global edge key (BlockMeshOut::border and
// foreign) so the extractor can weld block borders. The cubes a block visits are the closure of its seeds
// under "shares a crossed face", whatever the order of visiting, so the triangles are those of plain
// marching cubes over the same cubes.
#include <array>
#include <cstdint>
#include <span>

#include "jobs/lookup_cache.h"
#include "jobs/particle_spans.h"
#include "jobs/slice_field.h"

namespace rivulet {

// Words of one bit row for block edge n: a row holds n + 1 corners (bit_rows.h).
constexpr std::uint32_t row_words(std::uint32_t n) {
    return (n + 1 + 63) / 64;
}

// Scratch of one block sweep, for block edge n and W = row_words(n) (sizes in comments); reusable across
// blocks, nothing in it needs clearing between them.
struct SliceScratch {
    std::span<float> slices;                   // (n+1) * (n+1)^2: slice cache pool (corner values)
    std::span<std::uint64_t> face_bits;        // (n+1) W: one block face at a time
    std::span<std::uint64_t> slice_rows;       // 2 (n+1)^2 W: per slice, rows of corners computed and inside
    std::span<std::uint64_t> slab_rows;        // 2 n^2 W: per slab, rows of cubes queued and ever queued
    std::span<std::uint64_t> edge_rows;        // 3 (n+1)^2 W: per slice and axis, rows of edges with a vertex
    std::span<std::uint64_t> work_rows;        // 2 n W: the slab's frontier and the cubes it visited
    std::span<std::int32_t> slab_range;        // 2 n: per slab, the rows that may hold queued cubes
    std::span<std::uint32_t> edges;            // 3 (n+1)^3: the vertex on each edge with a vertex
    std::span<std::int32_t> walk_lo, walk_hi;  // (n+1)^2: inside run already walked per column
};

// Ownership of the vertices on block borders: a vertex belongs to the block holding the low corner of its
// edge (each block owns the vertices on its min faces and inside it). A block numbers the vertices it
// owns 0, 1, ... in the order it creates them (that number is the vertex's rank in the block's share of
// the mesh) and the ones another block owns down from the top of its buffers (capacity - 1, ...); it lists
// the owned vertices on one of its min faces (other blocks refer to them by key) and the foreign ones.
struct KeyedVertex {
    std::uint64_t key;    // edge_key of the vertex's edge
    std::uint32_t index;  // block-local vertex
};

struct BlockMeshOut {
    std::span<float> positions;          // 4 per vertex: x, y, z, 0 (angle_normals.h); capacity = size / 4
    std::span<std::uint32_t> triangles;  // 3 per triangle, block-local vertex indices
    std::span<KeyedVertex> border;       // owned vertices on a min face, in creation order
    std::span<KeyedVertex> foreign;      // vertices another block owns, in creation order
};

struct BlockSweepStats {
    // vertices = owned + foreign; owned vertices are 0 .. owned - 1, foreign ones capacity - foreign ..
    std::uint32_t vertices = 0, triangles = 0, owned = 0, border = 0, foreign = 0;
    std::uint32_t seeds = 0, cubes = 0, slice_fills = 0, peak_slices = 0;
    bool overflow = false;  // the output spans were too small: nothing usable, grow and run again
};

// Scratch sizes for block edge n.
struct SliceScratchSizes {
    std::size_t slices, face_bits, slice_rows, slab_rows, edge_rows, work_rows, slab_range, edges, columns;
    explicit SliceScratchSizes(std::uint32_t n)
        : slices(std::size_t(n + 1) * (n + 1) * (n + 1)),
          face_bits(std::size_t(n + 1) * row_words(n)),
          slice_rows(2 * std::size_t(n + 1) * (n + 1) * row_words(n)),
          slab_rows(2 * std::size_t(n) * n * row_words(n)),
          edge_rows(3 * std::size_t(n + 1) * (n + 1) * row_words(n)),
          work_rows(2 * std::size_t(n) * row_words(n)),
          slab_range(2 * std::size_t(n)),
          edges(3 * std::size_t(n + 1) * (n + 1) * (n + 1)),
          columns(std::size_t(n + 1) * (n + 1)) {}
};

// A face between two non-empty blocks, scanned once for both: the first block to claim it publishes its
// bit rows (F >= iso per corner, laid out as SliceScratch::face_bits) and the other reads them. Both
// blocks would compute the same bits (each lists every particle that reaches the face's corners, and a
// corner's sum runs over the same entries in the same global order), so which block scans it changes
// no byte of the output. A block that finds the face being scanned by the other scans it itself rather
// than wait.
struct SharedFace {
    std::uint32_t* state = nullptr;  // kFaceFree, kFaceBusy or kFaceDone (atomic_ref); null: not shared
    std::uint64_t* bits = nullptr;   // SliceScratchSizes::face_bits words
};
inline constexpr std::uint32_t kFaceFree = 0, kFaceBusy = 1, kFaceDone = 2;
// Face f = 2 * axis + side (side 1 is the +axis face), as in `empty_neighbours`.
using SharedFaces = std::array<SharedFace, 6>;

// One block's sweep: which block, what it reads and where it writes; the extractor fills one per block
// job and hands it to march_block with the block's lookup cache.
struct BlockSweepContext {
    const SliceGrid* grid = nullptr;
    std::uint32_t bi = 0, bj = 0, bk = 0;  // the block
    float iso = 0;
    ConstPositions particles;  // the block's particles, in its lookup cache's order
    SliceScratch scratch;      // one worker's
    BlockMeshOut out;
    // Also seed from every sign change along every z column of the block ((n+1)^3 corner evaluations),
    // which finds every component, empty cavities included, like plain marching cubes.
    bool exhaustive = false;
    // Bit 2 a + side is set when the neighbouring block across face (axis a, min side 0 / max side 1)
    // lists no particle: no particle reaches that face's corners, F = 0 on all of them, and the face scan
    // skips it.
    unsigned empty_neighbours = 0;
    SharedFaces shared = {};
};

// The sweep over a spherical-kernel cache, or an anisotropic one (jobs/anisotropic_kernels.h; the
// context's particles are then the smoothed centres).
BlockSweepStats march_block(const BlockSweepContext& block, const LookupCacheView& cache);
BlockSweepStats march_block(const BlockSweepContext& block, const AnisoLookupCacheView& cache);
// The x86-64 baseline build of march_block, which it runs where the CPU lacks AVX2 (or RIVULET_NO_AVX2
// is set); tests compare the two builds byte for byte.
BlockSweepStats march_block_baseline(const BlockSweepContext& block, const LookupCacheView& cache);
BlockSweepStats march_block_baseline(const BlockSweepContext& block, const AnisoLookupCacheView& cache);

}  // namespace rivulet
