// DESIGN §3.2: once running, a frame of the loop (simulation, extraction, upload, render) allocates
// nothing. Counted with a replaced global operator new.
#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"

#include "support/counting_new.h"

using namespace rivulet;

// The counter leaves out oneTBB's own pools only: it finds the library, and it counts what we allocate,
// from any thread.
TEST(SteadyState, TheCounterSeesOurAllocations) {
    const rivulet::test::CodeRange tbb = rivulet::test::tbb_code();
    EXPECT_LT(tbb.lo, tbb.hi);
    const long before = rivulet::test::allocation_count();
    auto* mine = new std::vector<int>(16);
    std::thread([] { delete new int(7); }).join();
    EXPECT_GE(rivulet::test::allocation_count() - before, 3);  // the vector, its elements, the int
    delete mine;
}

TEST(SteadyState, FrameLoopAllocatesNothing) {
    ThreadControl control(2);
    PipelineSettings config;
    config.size = {320, 180};
    config.hash_frames = true;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 60;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.reserve_records(200);
    pipeline.run(10);  // first frames may size GL buffers
    const long before = rivulet::test::allocation_count();
    pipeline.run(60);
    const long during = rivulet::test::allocation_count() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 60 steady-state frames";
    ASSERT_EQ(pipeline.records().size(), 70u);
}

// A diffuse object: update, compaction, emission, the radix sort, staging, the sprite upload and draw,
// with a collider crossing the object and particles dying and being born every frame.
TEST(SteadyState, DiffuseFrameLoopAllocatesNothing) {
    ThreadControl control(2);
    PipelineSettings config;
    config.method = SurfaceMethod::kSprites;
    config.size = {320, 180};
    config.hash_frames = true;
    SceneDesc scene = make_builtin_scene("ghost");
    scene.warmup_frames = 30;
    scene.max_particles = 20000;
    scene.diffuse.resolution = 24;
    scene.diffuse.colliders[0].period = 1.0f;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.reserve_records(200);
    pipeline.run(10);
    const long before = rivulet::test::allocation_count();
    pipeline.run(60);
    const long during = rivulet::test::allocation_count() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 60 steady-state frames";
}
