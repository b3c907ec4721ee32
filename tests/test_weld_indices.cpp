// jobs/weld_indices.h: block vertex numbers to mesh indices (owned ones shifted by the block's offset,
// foreign ones looked up), both builds against the rule written out per corner, on runs of owned corners
// with foreign ones scattered among them and at every position of a vector.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "jobs/weld_indices.h"

namespace {

using namespace rivulet;

struct Block {
    std::uint32_t capacity = 0;
    BlockVertexMap map;
    std::vector<std::uint32_t> foreign_mesh, local;
};

// Corners naming owned vertices [0, owned) and foreign ones [capacity - foreign, capacity), a foreign one
// with probability `foreign_share`.
Block random_block(unsigned seed, std::uint32_t owned, std::uint32_t foreign, std::size_t corners,
                   double foreign_share) {
    std::mt19937 rng(seed);
    Block b;
    b.capacity = owned + foreign + 100;  // unused slots in between, as in a block's buffers
    for (std::uint32_t q = 0; q < foreign; ++q) b.foreign_mesh.push_back(7'000'000u + 13u * q);
    std::bernoulli_distribution is_foreign(foreign_share);
    std::uniform_int_distribution<std::uint32_t> pick_owned(0, owned - 1), pick_foreign(0, foreign - 1);
    for (std::size_t t = 0; t < corners; ++t)
        b.local.push_back(is_foreign(rng) ? b.capacity - 1 - pick_foreign(rng) : pick_owned(rng));
    b.map = {owned, 123'456u, b.capacity - 1, b.foreign_mesh};
    return b;
}

std::vector<std::uint32_t> expected(const Block& b) {
    std::vector<std::uint32_t> out;
    for (std::uint32_t v : b.local)
        out.push_back(v < b.map.owned ? b.map.offset + v : b.foreign_mesh[b.capacity - 1 - v]);
    return out;
}

TEST(WeldIndices, OwnedVerticesShiftAndForeignOnesAreLookedUpInBothBuilds) {
    for (const double share : {0.0, 0.01, 0.2, 1.0})
        for (const std::size_t corners : {std::size_t(0), std::size_t(1), std::size_t(7), std::size_t(8),
                                          std::size_t(9), std::size_t(17), std::size_t(3000)}) {
            const Block b =
                random_block(unsigned(corners * 31) + unsigned(share * 1000), 500, 40, corners, share);
            const std::vector<std::uint32_t> want = expected(b);
            std::vector<std::uint32_t> got(corners, 0xdeadbeefu), base(corners, 0xdeadbeefu);
            weld_indices(b.local, b.map, got);
            weld_indices_baseline(b.local, b.map, base);
            EXPECT_EQ(got, want) << share << " " << corners;
            EXPECT_EQ(base, want) << share << " " << corners;
        }
}

TEST(WeldIndices, AForeignCornerAtAnyPositionOfAVectorIsLookedUp) {
    Block b = random_block(5, 300, 10, 64, 0.0);
    for (std::size_t at = 0; at < b.local.size(); ++at) {
        Block one = b;
        one.local[at] = one.capacity - 1 - std::uint32_t(at % 10);  // foreign vertex at % 10
        one.map.foreign = one.foreign_mesh;
        std::vector<std::uint32_t> got(one.local.size()), base(one.local.size());
        weld_indices(one.local, one.map, got);
        weld_indices_baseline(one.local, one.map, base);
        EXPECT_EQ(got, expected(one)) << at;
        EXPECT_EQ(base, expected(one)) << at;
        EXPECT_EQ(got[at], 7'000'000u + 13u * std::uint32_t(at % 10));
    }
}

TEST(WeldIndices, MeshIndicesAbove2To31AreShiftedExactly) {
    Block b = random_block(9, 400, 20, 257, 0.05);
    b.map.offset = 3'000'000'000u;  // a mesh past 2^31 vertices: the shifted indices do not fit int32
    std::vector<std::uint32_t> got(b.local.size()), base(b.local.size());
    weld_indices(b.local, b.map, got);
    weld_indices_baseline(b.local, b.map, base);
    EXPECT_EQ(got, expected(b));
    EXPECT_EQ(base, expected(b));
}

}  // namespace
