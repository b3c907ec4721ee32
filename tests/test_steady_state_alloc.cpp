// DESIGN §3.2: once running, a frame of the loop (simulation, extraction, upload, render) allocates
// nothing. Counted with a replaced global operator new.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    if (void* p = std::malloc(n ? n : 1)) return p;
    throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a) {
    g_allocations.fetch_add(1, std::memory_order_relaxed);
    const std::size_t al = static_cast<std::size_t>(a);
    if (void* p = std::aligned_alloc(al, (n + al - 1) / al * al)) return p;
    throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
    std::free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
    std::free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
    std::free(p);
}

using namespace rivulet;

TEST(SteadyState, FrameLoopAllocatesNothing) {
    ThreadControl control(2);
    PipelineConfig config;
    config.size = {320, 180};
    config.hash_frames = true;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 60;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.reserve_records(200);
    pipeline.run(10);  // first frames may size GL buffers
    const long before = g_allocations.load();
    pipeline.run(60);
    const long during = g_allocations.load() - before;
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in 60 steady-state frames";
    ASSERT_EQ(pipeline.records().size(), 70u);
}
