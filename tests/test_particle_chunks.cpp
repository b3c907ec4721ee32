// The one way parallel jobs cut a frame's particles (jobs/particle_chunks.h): consecutive ranges that
// cover every particle once, in order, with a count that depends on the particles alone.
#include <gtest/gtest.h>

#include <cstddef>

#include "jobs/particle_chunks.h"
#include "jobs/particle_spans.h"

using rivulet::ParticleChunks;
using rivulet::ParticleRange;

TEST(ParticleChunks, RangesCoverEveryParticleOnceInOrder) {
    for (const std::size_t size : {std::size_t(1), std::size_t(7), rivulet::kParticleChunk})
        for (const std::size_t n : {std::size_t(0), std::size_t(1), size - 1, size, size + 1, 5 * size + 3}) {
            const ParticleChunks cut{size};
            const std::size_t chunks = cut.count(n);
            EXPECT_EQ(chunks, (n + size - 1) / size) << n << " of " << size;
            std::size_t next = 0;
            for (std::size_t c = 0; c < chunks; ++c) {
                const ParticleRange r = cut.range(c, n);
                EXPECT_EQ(r.begin, next) << "chunk " << c;
                EXPECT_GT(r.count, 0u) << "chunk " << c;
                EXPECT_LE(r.count, size);
                EXPECT_TRUE(c + 1 == chunks || r.count == size) << "only the last chunk is short";
                next = r.end();
            }
            EXPECT_EQ(next, n);
            const ParticleRange past = cut.range(chunks + 2, n);  // an item beyond the frame's particles
            EXPECT_EQ(past.begin, n);
            EXPECT_EQ(past.count, 0u);
        }
}

TEST(ParticleChunks, AtMostBoundsTheChunkCountAndTheSmallestChunk) {
    for (const std::size_t max_particles : {0, 1, 4095, 4096, 65536, 65537, 1000000}) {
        const ParticleChunks cut = ParticleChunks::at_most(max_particles, 16);
        EXPECT_GE(cut.size, rivulet::kParticleChunk);
        EXPECT_LE(cut.count(max_particles), 16u) << max_particles;
        for (std::size_t n = 0; n <= max_particles; n += max_particles / 7 + 1) EXPECT_LE(cut.count(n), 16u);
    }
    EXPECT_EQ(ParticleChunks::at_most(100, 4, 10).size, 25u);
    EXPECT_EQ(ParticleChunks::at_most(100, 40, 10).size, 10u);
}

TEST(ParticleChunks, PositionsSubspanIsTheSameRangeOfEachArray) {
    const float x[] = {0, 1, 2, 3, 4}, y[] = {10, 11, 12, 13, 14}, z[] = {20, 21, 22, 23, 24};
    const rivulet::ConstPositions p{x, y, z};
    const ParticleRange r = ParticleChunks{2}.range(1, p.size());
    const rivulet::ConstPositions part = p.subspan(r.begin, r.count);
    ASSERT_EQ(part.size(), 2u);
    EXPECT_EQ(part.x[0], 2.0f);
    EXPECT_EQ(part.y[1], 13.0f);
    EXPECT_EQ(part.z[0], 22.0f);
}
