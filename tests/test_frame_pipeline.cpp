// The frame loop end to end: same bytes at 1 and 2 threads, and a rendered default-scene frame that
// shows water where the stream is.
#include <gtest/gtest.h>

#include <vector>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "systems/render/camera.h"

using namespace rivulet;

namespace {

std::vector<std::uint64_t> frame_hashes(int threads, int frames) {
    ThreadControl control(threads);
    PipelineConfig config;
    config.render = false;
    config.hash_frames = true;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 30;
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.run(frames);
    std::vector<std::uint64_t> hashes;
    for (const FrameRecord& r : pipeline.records()) hashes.push_back(r.hash);
    return hashes;
}

bool water_blue(const std::uint8_t* px) {
    return px[2] > px[0] + 40 && px[2] > 90;
}

}  // namespace

TEST(FramePipeline, SameMeshHashesAtOneAndTwoThreadsOver100Frames) {
    const auto one = frame_hashes(1, 100);
    const auto two = frame_hashes(2, 100);
    ASSERT_EQ(one.size(), 100u);
    for (std::size_t i = 0; i < one.size(); ++i) ASSERT_EQ(one[i], two[i]) << "frame " << i << " differs";
    // The hashes really follow the surface: consecutive frames of a moving fountain differ.
    EXPECT_NE(one[0], one[1]);
}

TEST(FramePipeline, DefaultSceneFrameShowsWaterWhereTheStreamIs) {
    ThreadControl control(2);
    PipelineConfig config;
    config.size = {320, 180};
    const SceneDesc scene = make_builtin_scene("fountain");
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.run(1);
    ASSERT_NE(pipeline.renderer(), nullptr);
    std::vector<std::uint8_t> rgba(320 * 180 * 4);
    pipeline.renderer()->read_rgba(rgba);

    // Every particle of the rendered frame, projected: its pixel should be water-coloured.
    const ConstPositions p = pipeline.particles().positions();
    ASSERT_GT(p.size(), 5000u);
    std::size_t seen = 0, blue = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        float px = 0, py = 0;
        if (!project_to_pixel(scene.camera, 320, 180, {p.x[i], p.y[i], p.z[i]}, px, py)) continue;
        const auto x = static_cast<int>(px), y = static_cast<int>(py);
        ++seen;
        blue += water_blue(&rgba[(std::size_t(y) * 320 + std::size_t(x)) * 4]) ? 1 : 0;
    }
    ASSERT_GT(seen, p.size() / 2);
    // A few centres sit behind the nozzle column or inside the pool's rim: most must show water.
    EXPECT_GT(static_cast<double>(blue) / static_cast<double>(seen), 0.75);
    // And the sky at the top of the picture is not water.
    std::size_t sky_blue = 0;
    for (int x = 0; x < 320; ++x) sky_blue += water_blue(&rgba[std::size_t(x) * 4]) ? 1 : 0;
    EXPECT_EQ(sky_blue, 0u);
}
