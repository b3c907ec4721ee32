// DESIGN §3.2 for marching slices: once its buffers have grown to the frames it sees, a frame of the
// slices.* jobs allocates nothing. Counted with a replaced global operator new.
#include <gtest/gtest.h>

#include <cmath>

#include "runtime/lib/frame_graph.h"
#include "runtime/lib/slices_jobs.h"
#include "runtime/lib/thread_control.h"
#include "systems/particles/particle_set.h"

#include "support/counting_new.h"

using namespace rivulet;

class SlicesSteadyState : public ::testing::TestWithParam<float> {};

TEST_P(SlicesSteadyState, FramesAllocateNothing) {
    ThreadControl control(2);
    const std::size_t n = 3000;
    ParticleSet a(n), b(n);
    for (std::uint32_t i = 0; i < n; ++i) {  // a swirl of particles, and the same swirl turned a little
        const float t = 0.01f * float(i), r = 0.3f + 0.1f * std::sin(3 * t);
        a.push(r * std::cos(t), 0.02f * t, r * std::sin(t), 0, 0, 0, i);
        b.push(r * std::cos(t + 0.1f), 0.02f * t, r * std::sin(t + 0.1f), 0, 0, 0, i);
    }
    SlicesSettings s;
    s.radius = 0.03f;
    s.block_cubes = 8;
    s.anisotropy = GetParam();
    SlicesExtractor slices(s, n);
    slices.reserve_scratch(2);
    SurfaceMesh mesh;
    int frame = 0;
    FrameGraph graph;
    add_slices_jobs(
        graph, slices, [&] { return (frame % 2 ? b : a).positions(); },
        [&mesh]() -> SurfaceMesh& { return mesh; });
    for (; frame < 8; ++frame) graph.run();  // buffers and per-worker scratch grow here
    const long before = rivulet::test::allocation_count();
    for (; frame < 28; ++frame) graph.run();
    const long during = rivulet::test::allocation_count() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 20 steady-state frames";
    EXPECT_GT(mesh.triangle_count(), 1000u);
}

INSTANTIATE_TEST_SUITE_P(Kernels, SlicesSteadyState, ::testing::Values(0.0f, kDefaultAnisotropy),
                         [](const auto& p) { return p.param > 0 ? "Anisotropic" : "Spheres"; });

// Frames under SlicesExtractor::kSpacingSamples particles are each measured for themselves, so R_c (and
// with it the lookup cache's reach) can grow from one frame to the next: a sparse frame after a dense one
// must not overrun the sweep scratch the dense frame sized (a fountain's first frames).
TEST(SlicesFrames, AWiderFieldAfterANarrowerOneFitsItsScratch) {
    ThreadControl control(2);
    SlicesSettings s;
    s.radius = 0.012f;
    s.block_cubes = 8;
    SlicesExtractor slices(s, 1000);
    SurfaceMesh mesh;
    ParticleSet frames[2] = {ParticleSet(1000), ParticleSet(1000)};
    const float spacing[2] = {0.008f, 0.03f};  // R_c follows the spacing: narrow, then wide
    for (int f = 0; f < 2; ++f)
        for (int i = 0, id = 0; i < 9; ++i)
            for (int j = 0; j < 9; ++j)
                for (int k = 0; k < 9; ++k)
                    frames[f].push(spacing[f] * float(i), spacing[f] * float(j), spacing[f] * float(k), 0, 0,
                                   0, static_cast<std::uint32_t>(id++));
    int frame = 0;
    FrameGraph graph;
    add_slices_jobs(
        graph, slices, [&] { return frames[frame % 2].positions(); },
        [&mesh]() -> SurfaceMesh& { return mesh; });
    float rc[2] = {0, 0};
    for (; frame < 4; ++frame) {
        graph.run();
        rc[frame % 2] = slices.rc();
        EXPECT_GT(mesh.triangle_count(), 100u) << "frame " << frame;
    }
    EXPECT_GT(rc[1], 1.5f * rc[0]);
}
