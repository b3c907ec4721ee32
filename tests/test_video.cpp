// run --video (docs/video.md): what VideoWriter encodes decodes back to the same pictures, in order, at the
// scene's frame rate; bad paths fail with one clear message; the frame loop stays allocation-free.
#include <gtest/gtest.h>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/frame.h>
}

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "support/counting_new.h"
#include "support/test_support.h"
#include "systems/render/video_writer.h"

using namespace rivulet;
using rivulet::test::temp_path;

namespace {

struct Decoded {
    std::string codec;
    int width = 0, height = 0;
    AVRational rate{0, 1};
    AVColorSpace colorspace = AVCOL_SPC_UNSPECIFIED;
    AVColorRange range = AVCOL_RANGE_UNSPECIFIED;
    std::vector<std::vector<std::uint8_t>> frames;  // RGBA, rows top to bottom
};

// Limited-range BT.709 yuv420p to RGBA by the formula, in double: swscale's own conversion back is only
// good to about 3 levels, which would hide the encoder's error in the test's.
std::vector<std::uint8_t> bt709_to_rgba(const AVFrame& f) {
    const int w = f.width, h = f.height;
    std::vector<std::uint8_t> rgba(std::size_t(w) * std::size_t(h) * 4);
    const auto clamp8 = [](double v) {
        return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
    };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double luma = (f.data[0][y * f.linesize[0] + x] - 16.0) * 255.0 / 219.0;
            const double cb = (f.data[1][(y / 2) * f.linesize[1] + x / 2] - 128.0) * 255.0 / 224.0;
            const double cr = (f.data[2][(y / 2) * f.linesize[2] + x / 2] - 128.0) * 255.0 / 224.0;
            std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4];
            p[0] = clamp8(luma + 1.5748 * cr);
            p[1] = clamp8(luma - 0.1873 * cb - 0.4681 * cr);
            p[2] = clamp8(luma + 1.8556 * cb);
            p[3] = 255;
        }
    return rgba;
}

// Decodes every frame of `path` with libavformat/libavcodec, as a player would, and converts it back to
// RGBA (BT.709, limited range: what the writer tags and the test checks).
Decoded decode(const std::string& path) {
    Decoded d;
    AVFormatContext* format = nullptr;
    if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0)
        throw std::runtime_error("cannot open " + path);
    std::unique_ptr<AVFormatContext, void (*)(AVFormatContext*)> format_guard(
        format, [](AVFormatContext* f) { avformat_close_input(&f); });
    if (avformat_find_stream_info(format, nullptr) < 0) throw std::runtime_error("no stream info");
    const int index = av_find_best_stream(format, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
    if (index < 0) throw std::runtime_error("no video stream");
    const AVStream* stream = format->streams[index];
    const AVCodec* decoder = avcodec_find_decoder(stream->codecpar->codec_id);
    if (!decoder) throw std::runtime_error("no decoder");
    std::unique_ptr<AVCodecContext, void (*)(AVCodecContext*)> ctx(
        avcodec_alloc_context3(decoder), [](AVCodecContext* c) { avcodec_free_context(&c); });
    avcodec_parameters_to_context(ctx.get(), stream->codecpar);
    ctx->thread_count = 1;
    if (avcodec_open2(ctx.get(), decoder, nullptr) < 0) throw std::runtime_error("cannot open the decoder");
    d.codec = avcodec_get_name(stream->codecpar->codec_id);
    d.width = stream->codecpar->width;
    d.height = stream->codecpar->height;
    d.rate = stream->avg_frame_rate;

    std::unique_ptr<AVPacket, void (*)(AVPacket*)> packet(av_packet_alloc(),
                                                          [](AVPacket* p) { av_packet_free(&p); });
    std::unique_ptr<AVFrame, void (*)(AVFrame*)> frame(av_frame_alloc(),
                                                       [](AVFrame* f) { av_frame_free(&f); });
    const auto receive = [&] {
        while (avcodec_receive_frame(ctx.get(), frame.get()) == 0) {
            if (frame->format != AV_PIX_FMT_YUV420P) throw std::runtime_error("not yuv420p");
            d.colorspace = frame->colorspace;
            d.range = frame->color_range;
            d.frames.push_back(bt709_to_rgba(*frame));
        }
    };
    while (av_read_frame(format, packet.get()) >= 0) {
        if (packet->stream_index == index) {
            avcodec_send_packet(ctx.get(), packet.get());
            receive();
        }
        av_packet_unref(packet.get());
    }
    avcodec_send_packet(ctx.get(), nullptr);
    receive();
    return d;
}

// Frame f of the synthetic clip: four quadrants, each a solid colour that changes every frame, so a frame
// out of place or a swapped channel shows.
std::array<std::uint8_t, 3> quadrant_colour(int f, int q) {
    return {static_cast<std::uint8_t>((30 + 37 * f + 60 * q) % 200 + 28),
            static_cast<std::uint8_t>((170 + 23 * f + 90 * q) % 200 + 28),
            static_cast<std::uint8_t>((90 + 53 * f + 25 * q) % 200 + 28)};
}

std::vector<std::uint8_t> synthetic_frame(int f, int w, int h) {
    std::vector<std::uint8_t> rgba(std::size_t(w) * std::size_t(h) * 4);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const auto c = quadrant_colour(f, (y >= h / 2 ? 2 : 0) + (x >= w / 2 ? 1 : 0));
            std::uint8_t* p = &rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4];
            p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
        }
    return rgba;
}

// Mean of each channel over the rectangle [x0, x1) x [y0, y1).
std::array<double, 3> mean_rgb(const std::vector<std::uint8_t>& rgba, int w, int x0, int y0, int x1, int y1) {
    std::array<double, 3> sum{};
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            for (int c = 0; c < 3; ++c)
                sum[c] += rgba[(std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4 + c];
    const double n = double(x1 - x0) * double(y1 - y0);
    for (double& s : sum) s /= n;
    return sum;
}

// The decoded clip shows each frame's quadrant colours, in order, within `tolerance` levels (lossy codec;
// the means leave out a margin where chroma subsampling blends neighbouring quadrants).
void expect_synthetic_clip(const Decoded& d, int frames, int w, int h, double tolerance) {
    ASSERT_EQ(d.width, w);
    ASSERT_EQ(d.height, h);
    ASSERT_EQ(int(d.frames.size()), frames);
    const int m = 6;
    for (int f = 0; f < frames; ++f)
        for (int q = 0; q < 4; ++q) {
            const int x0 = (q % 2) * w / 2, y0 = (q / 2) * h / 2;
            const auto mean = mean_rgb(d.frames[f], w, x0 + m, y0 + m, x0 + w / 2 - m, y0 + h / 2 - m);
            const auto want = quadrant_colour(f, q);
            for (int c = 0; c < 3; ++c)
                EXPECT_NEAR(mean[c], want[c], tolerance)
                    << "frame " << f << " quadrant " << q << " channel " << c;
        }
}

void write_synthetic_clip(const std::string& path, int frames, int w, int h, double fps,
                          VideoCodec codec = VideoCodec::kAuto) {
    VideoWriter v;
    v.open(path, w, h, fps, codec);
    for (int f = 0; f < frames; ++f) v.write(synthetic_frame(f, w, h));
    EXPECT_EQ(v.frames(), frames);
    v.finish();
    EXPECT_FALSE(v.is_open());
}

std::string read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}

bool libx264_present() {
    return avcodec_find_encoder_by_name("libx264") != nullptr;
}

class Video : public ::testing::Test {
  protected:
    void SetUp() override { silence_video_library_log(); }
};

}  // namespace

TEST(VideoFrameRate, NamesTheFractionAFloatDtMeant) {
    const auto rate = [](float dt) { return video_frame_rate(1.0 / double(dt)); };
    EXPECT_EQ(rate(1.0f / 60.0f).num, 60);
    EXPECT_EQ(rate(1.0f / 60.0f).den, 1);
    EXPECT_EQ(rate(1.0f / 24.0f).num, 24);
    EXPECT_EQ(rate(0.03f).num, 100);
    EXPECT_EQ(rate(0.03f).den, 3);
    EXPECT_EQ(rate(1.0f / 144.0f).num, 144);
    // A float cannot tell 30000/1001 from nearby fractions; what comes out is as close as dt is.
    EXPECT_NEAR(rate(1001.0f / 30000.0f).fps(), 30000.0 / 1001.0, 1e-5);
    EXPECT_EQ(rate(1.0f).num, 1);
    EXPECT_NEAR(rate(0.0123457f).fps(), 1.0 / 0.0123457, 1e-3);
    EXPECT_THROW(video_frame_rate(0), std::invalid_argument);
    EXPECT_THROW(video_frame_rate(std::nan("")), std::invalid_argument);
}

TEST_F(Video, H264DecodesBackToTheSameColoursInOrder) {
    if (!libx264_present()) GTEST_SKIP() << "libavcodec without libx264";
    const std::string path = temp_path("clip.mp4");
    write_synthetic_clip(path, 12, 96, 64, 60);
    const Decoded d = decode(path);
    EXPECT_EQ(d.codec, "h264");
    // Tagged as converted, so players use the same matrix and range.
    EXPECT_EQ(d.colorspace, AVCOL_SPC_BT709);
    EXPECT_EQ(d.range, AVCOL_RANGE_MPEG);
    EXPECT_EQ(d.rate.num, 60);
    EXPECT_EQ(d.rate.den, 1);
    expect_synthetic_clip(d, 12, 96, 64, 4);
}

TEST_F(Video, Mpeg4DecodesBackToTheSameColoursInOrder) {
    const std::string path = temp_path("clip_mpeg4.mp4");
    write_synthetic_clip(path, 12, 96, 64, 60, VideoCodec::kMpeg4);
    const Decoded d = decode(path);
    EXPECT_EQ(d.codec, "mpeg4");
    EXPECT_EQ(d.colorspace, AVCOL_SPC_BT709);
    EXPECT_EQ(d.range, AVCOL_RANGE_MPEG);
    EXPECT_EQ(d.rate.num, 60);
    EXPECT_EQ(d.rate.den, 1);
    expect_synthetic_clip(d, 12, 96, 64, 4);
}

TEST_F(Video, OtherContainersAndAFractionalRate) {
    for (const char* name : {"clip.mkv", "clip.mov", "clip.avi"}) {
        const std::string path = temp_path(name);
        write_synthetic_clip(path, 8, 64, 48, 1.0 / double(0.03f));  // 100/3 frames per second
        const Decoded d = decode(path);
        EXPECT_NEAR(av_q2d(d.rate), 100.0 / 3.0, 0.01) << name;
        expect_synthetic_clip(d, 8, 64, 48, 4);
    }
}

TEST_F(Video, TheSameFramesGiveTheSameBytes) {
    for (VideoCodec codec : {VideoCodec::kAuto, VideoCodec::kMpeg4}) {
        const std::string a = temp_path("same_a.mp4"), b = temp_path("same_b.mp4");
        write_synthetic_clip(a, 10, 64, 48, 60, codec);
        write_synthetic_clip(b, 10, 64, 48, 60, codec);
        const std::string bytes = read_bytes(a);
        EXPECT_GT(bytes.size(), 100u);
        EXPECT_TRUE(bytes == read_bytes(b)) << "two encodes of the same frames differ";
    }
}

TEST_F(Video, ReportsWhatItWrites) {
    VideoWriter v;
    EXPECT_FALSE(v.is_open());
    v.open(temp_path("report.mp4"), 64, 48, 1.0 / double(1.0f / 60.0f));
    EXPECT_TRUE(v.is_open());
    EXPECT_EQ(v.width(), 64);
    EXPECT_EQ(v.height(), 48);
    EXPECT_EQ(v.frame_rate().num, 60);
    EXPECT_EQ(v.frame_rate().den, 1);
    EXPECT_EQ(v.codec_name(), libx264_present() ? "libx264" : "mpeg4");
    EXPECT_FALSE(v.codec_description().empty());
    v.write(synthetic_frame(0, 64, 48));
    v.finish();
    v.finish();  // a second finish does nothing
    EXPECT_EQ(v.frames(), 1);
    EXPECT_EQ(decode(temp_path("report.mp4")).frames.size(), 1u);
}

TEST_F(Video, BadPathsAndSizesFailWithTheirReason) {
    const std::string dir = temp_path("video_dir.mp4");
    std::filesystem::create_directories(dir);
    struct Case {
        std::string path;
        int w, h;
        double fps;
        std::string expect;
    };
    for (const Case& c : std::vector<Case>{
             {"/nonexistent/dir/x.mp4", 64, 48, 60, "No such file"},
             {temp_path("x.nosuchformat"), 64, 48, 60, ".nosuchformat"},
             {temp_path("no_extension"), 64, 48, 60, "no extension"},
             {dir, 64, 48, 60, "directory"},
             {temp_path("x.wav"), 64, 48, 60, "no video"},
             {temp_path("x.webm"), 64, 48, 60, "neither H.264 nor MPEG-4"},
             {temp_path("x_%03d.png"), 64, 48, 60, "no single video file"},
             {temp_path("odd.mp4"), 65, 48, 60, "odd"},
             {temp_path("odd.mp4"), 64, 47, 60, "odd"},
             {temp_path("empty.mp4"), 0, 48, 60, "empty"},
             {temp_path("slow.mp4"), 64, 48, 0.5, "frames per second"},
             {temp_path("fast.mp4"), 64, 48, 5000, "frames per second"},
         }) {
        VideoWriter v;
        try {
            v.open(c.path, c.w, c.h, c.fps);
            ADD_FAILURE() << c.path << " " << c.w << "x" << c.h << " opened";
        } catch (const std::runtime_error& e) {
            const std::string what = e.what();
            EXPECT_NE(what.find(c.expect), std::string::npos) << what;
            EXPECT_NE(what.find(c.path), std::string::npos) << "the message names the path: " << what;
        }
        EXPECT_FALSE(v.is_open());
    }
    for (const char* left : {"x.nosuchformat", "odd.mp4", "empty.mp4", "slow.mp4", "x.wav", "x.webm"})
        EXPECT_FALSE(std::filesystem::exists(temp_path(left))) << left << " was left behind";
}

TEST_F(Video, MisuseIsRefused) {
    VideoWriter v;
    EXPECT_THROW(v.write(synthetic_frame(0, 64, 48)), std::logic_error);
    v.open(temp_path("misuse.mp4"), 64, 48, 60);
    EXPECT_THROW(v.open(temp_path("misuse2.mp4"), 64, 48, 60), std::logic_error);
    const std::vector<std::uint8_t> short_frame(64 * 48 * 4 - 1);
    EXPECT_THROW(v.write(short_frame), std::invalid_argument);
    v.write(synthetic_frame(0, 64, 48));
    v.finish();
    EXPECT_THROW(v.write(synthetic_frame(1, 64, 48)), std::logic_error);
    EXPECT_EQ(decode(temp_path("misuse.mp4")).frames.size(), 1u);
}

TEST_F(Video, TheDestructorCompletesTheFile) {
    const std::string path = temp_path("unfinished.mp4");
    {
        VideoWriter v;
        v.open(path, 64, 48, 60);
        for (int f = 0; f < 5; ++f) v.write(synthetic_frame(f, 64, 48));
    }
    expect_synthetic_clip(decode(path), 5, 64, 48, 4);
}

// The frame loop with a video: frames reach the encoder in order although it runs off the main thread,
// each video frame is the picture rendered then, and the steady state allocates nothing of ours.
TEST_F(Video, TheFrameLoopEncodesEveryRenderedFrameInOrderWithoutAllocating) {
    const int w = 160, h = 90, frames = 40, warm = 10;
    const std::string path = temp_path("pipeline.mp4");
    std::vector<std::vector<std::uint8_t>> rendered(frames,
                                                    std::vector<std::uint8_t>(std::size_t(w) * h * 4));
    long during = -1;
    {
        ThreadControl control(2);
        PipelineSettings config;
        config.size = {w, h};
        config.out_dir = "";
        config.video_path = path;
        SceneDesc scene = make_builtin_scene("fountain");
        scene.warmup_frames = 30;
        // Dark, opaque water: moving droplets change the pictures in brightness, which the codec keeps
        // (clear water over a pale floor changes them in faint tints, lost at this size).
        scene.look.water.color = {0.02f, 0.02f, 0.08f};
        scene.look.water.absorption = {200, 200, 200};
        FramePipeline pipeline(scene, config);
        ASSERT_NE(pipeline.video(), nullptr);
        pipeline.warmup();
        pipeline.reserve_records(frames);
        int done = 0;
        // Built before the count starts: std::function would allocate for these captures.
        const std::function<void(int)> keep = [&](int) {
            pipeline.renderer()->read_rgba(rendered[std::size_t(done++)]);
        };
        pipeline.run(warm, keep);
        const long before = rivulet::test::allocation_count();
        pipeline.run(frames - warm, keep);
        during = rivulet::test::allocation_count() - before;
        pipeline.finish_video();
        EXPECT_EQ(pipeline.video()->frames(), frames);
    }
    EXPECT_EQ(during, 0) << "operator new called " << during << " times in " << frames - warm << " frames";
    const Decoded d = decode(path);
    ASSERT_EQ(int(d.frames.size()), frames);
    EXPECT_EQ(d.rate.num, 60);
    EXPECT_EQ(d.rate.den, 1);
    // Mean absolute difference of 8x8 block means: the codec's error at this small size is mostly fine
    // detail (droplet edges, 4:2:0 chroma), which block means average out.
    const auto distance = [&](const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
        double sum = 0;
        for (int by = 0; by + 8 <= h; by += 8)
            for (int bx = 0; bx + 8 <= w; bx += 8) {
                const auto ma = mean_rgb(a, w, bx, by, bx + 8, by + 8),
                           mb = mean_rgb(b, w, bx, by, bx + 8, by + 8);
                for (int c = 0; c < 3; ++c) sum += std::abs(ma[c] - mb[c]);
            }
        return sum / double((w / 8) * (h / 8) * 3);
    };
    // Over the pixels where pictures f and g differ clearly (droplets that moved): the decoded frame f's
    // mean distance to picture f and to picture g.
    struct Split {
        double to_own = 0, to_other = 0;
        std::size_t pixels = 0;
    };
    const auto where_they_differ = [&](int f, int g) {
        Split s;
        for (std::size_t p = 0; p < std::size_t(w) * h; ++p) {
            int change = 0;
            for (std::size_t c = 0; c < 3; ++c)
                change += std::abs(rendered[f][p * 4 + c] - rendered[g][p * 4 + c]);
            if (change < 90) continue;
            ++s.pixels;
            for (std::size_t c = 0; c < 3; ++c) {
                s.to_own += std::abs(double(d.frames[f][p * 4 + c]) - rendered[f][p * 4 + c]);
                s.to_other += std::abs(double(d.frames[f][p * 4 + c]) - rendered[g][p * 4 + c]);
            }
        }
        return s;
    };
    int compared = 0;
    for (int f = 0; f < frames; ++f) {
        EXPECT_LT(distance(d.frames[f], rendered[f]), 2.5) << "frame " << f;
        // In order: where the pictures before and after differ from frame f's, the decoded frame shows f's.
        for (int g : {f - 1, f + 1}) {
            if (g < 0 || g >= frames) continue;
            const Split s = where_they_differ(f, g);
            if (s.pixels < 20) continue;
            ++compared;
            EXPECT_LT(s.to_own, s.to_other) << "frame " << f << " against " << g;
        }
    }
    EXPECT_GT(compared, frames) << "the pictures hardly differ: order is not tested";
}

TEST(VideoCli, RunWritesAVideoOfEveryFrame) {
    const std::string path = temp_path("cli.mp4"), path1 = temp_path("cli1.mp4");
    const rivulet::test::Result r = rivulet::test::run_cli(
        "run --frames 3 --threads 2 --size 160x90 --warmup 10 --out '' --video " + path);
    ASSERT_EQ(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("video: " + path), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("160x90"), std::string::npos) << r.output;
    const Decoded d = decode(path);
    EXPECT_EQ(d.frames.size(), 3u);
    EXPECT_EQ(d.width, 160);
    EXPECT_EQ(d.height, 90);
    EXPECT_EQ(d.rate.num, 60);
    EXPECT_EQ(d.rate.den, 1);
    // Same pictures at any thread count, one encoder thread: same bytes.
    ASSERT_EQ(rivulet::test::run_cli(
                  "run --frames 3 --threads 1 --size 160x90 --warmup 10 --out '' --video " + path1)
                  .status,
              0);
    EXPECT_TRUE(read_bytes(path) == read_bytes(path1)) << "the video differs between 1 and 2 threads";
}

TEST(VideoCli, BadVideoOptionsFailAtOnceWithOneLine) {
    struct Case {
        std::string args, expect;
        int status;
    };
    for (const Case& c : std::vector<Case>{
             {"--size 160x90 --video /nonexistent/dir/x.mp4", "/nonexistent/dir/x.mp4", 1},
             {"--size 160x90 --video " + temp_path("x.nosuchformat"), ".nosuchformat", 1},
             {"--size 161x90 --video " + temp_path("odd.mp4"), "even", 1},
             {"--size 160x90 --video " + temp_path("norender.mp4") + " --no-render", "--no-render", 2},
         }) {
        const auto t0 = std::chrono::steady_clock::now();
        const rivulet::test::Result r = rivulet::test::run_cli("run --frames 500 --out '' " + c.args);
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        EXPECT_EQ(r.status, c.status) << c.args << ": " << r.output;
        EXPECT_EQ(r.output.rfind("rivulet: error: ", 0), 0u) << c.args << ": " << r.output;
        EXPECT_NE(r.output.find(c.expect), std::string::npos) << c.args << ": " << r.output;
        EXPECT_EQ(r.output.find('\n'), r.output.size() - 1) << "one line: " << r.output;
        // Checked before the simulation: 500 frames would take many seconds.
        EXPECT_LT(seconds, 5.0) << c.args;
    }
}

TEST(VideoCli, AFailedVideoWriteStopsTheRunWithAMessage) {
#if defined(__SANITIZE_THREAD__)
    GTEST_SKIP() << "ThreadSanitizer's runtime dies at start-up (SIGBUS) under a file size limit below 1 MiB";
#endif
    // A file size limit makes the writes fail part-way (EFBIG: SIGXFSZ ignored), like a full disk.
    const std::string path = temp_path("too_big.mp4");
    const rivulet::test::Result r = rivulet::test::run_cli(
        "run --frames 30 --threads 2 --size 320x180 --warmup 5 --out '' --video " + path,
        "trap '' XFSZ; ulimit -f 8;");
    EXPECT_NE(r.status, 0) << r.output;
    EXPECT_NE(r.output.find("rivulet: error: writing video '" + path + "' failed"), std::string::npos)
        << r.output;
    EXPECT_EQ(r.output.find("terminate"), std::string::npos) << r.output;
}
