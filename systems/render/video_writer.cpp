#include "systems/render/video_writer.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/avutil.h>
#include <libavutil/frame.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <fmt/format.h>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace rivulet {
namespace {

std::string av_error(int code) {
    char text[AV_ERROR_MAX_STRING_SIZE] = {};
    av_strerror(code, text, sizeof text);
    return text;
}

std::runtime_error cannot_write(const std::string& path, const std::string& why) {
    return std::runtime_error(fmt::format("cannot write video '{}': {}", path, why));
}

std::runtime_error write_failed(const std::string& path, const std::string& why) {
    return std::runtime_error(fmt::format("writing video '{}' failed: {}", path, why));
}

// 1 when the container surely takes the codec, 0 when it surely does not, < 0 when it cannot tell
// (formats without a codec table, e.g. MPEG-TS): those are tried, and the header write has the last word.
int container_takes(const AVOutputFormat* format, const AVCodec* codec) {
    return codec ? avformat_query_codec(format, codec->id, FF_COMPLIANCE_NORMAL) : 0;
}

const AVCodec* pick_encoder(const AVOutputFormat* format, VideoCodec choice) {
    const AVCodec* x264 = choice == VideoCodec::kAuto ? avcodec_find_encoder_by_name("libx264") : nullptr;
    const AVCodec* mpeg4 = avcodec_find_encoder(AV_CODEC_ID_MPEG4);
    for (const AVCodec* c : {x264, mpeg4})
        if (container_takes(format, c) == 1) return c;
    for (const AVCodec* c : {x264, mpeg4})
        if (container_takes(format, c) < 0) return c;
    return nullptr;
}

}  // namespace

VideoFrameRate video_frame_rate(double fps) {
    if (!std::isfinite(fps) || fps <= 0)
        throw std::invalid_argument(fmt::format("video frame rate {} is not a positive number", fps));
    // A float dt is only within half a float ulp (2^-24, relative) of the time the scene meant, and so is
    // 1/dt of the rate; the smallest denominator that lands that close names the intended fraction.
    const double tolerance = 0x1.02p-24 * fps;
    for (int den = 1; den <= 1001; ++den) {
        const double num = std::round(fps * den);
        if (num >= 1 && num <= 1e9 && std::abs(num / den - fps) <= tolerance)
            return {static_cast<int>(num), den};
    }
    const AVRational q = av_d2q(fps, 65535);
    return {q.num, q.den};
}

struct VideoWriter::Impl {
    std::string path;
    int width = 0, height = 0;
    VideoFrameRate rate;
    std::string codec_name, codec_description;
    std::int64_t frames = 0;
    bool finished = false;

    AVFormatContext* format = nullptr;
    AVCodecContext* codec = nullptr;
    AVStream* stream = nullptr;  // owned by `format`
    AVFrame* frame = nullptr;
    AVPacket* packet = nullptr;
    SwsContext* sws = nullptr;
    bool file_open = false;

    ~Impl() { release(); }

    void release() {
        sws_freeContext(sws);
        sws = nullptr;
        av_packet_free(&packet);
        av_frame_free(&frame);
        avcodec_free_context(&codec);
        if (format) {
            if (file_open) avio_closep(&format->pb);
            file_open = false;
            avformat_free_context(format);
            format = nullptr;
            stream = nullptr;
        }
    }

    // Sends a frame (null: end of stream) and writes every packet the encoder has ready.
    void encode(const AVFrame* f) {
        int rc = avcodec_send_frame(codec, f);
        if (rc < 0) throw write_failed(path, "the encoder refused a frame: " + av_error(rc));
        for (;;) {
            rc = avcodec_receive_packet(codec, packet);
            if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
            if (rc < 0) throw write_failed(path, "the encoder failed: " + av_error(rc));
            // The muxer may have chosen its own time base in the header (MP4: a multiple of the rate).
            av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
            packet->stream_index = stream->index;
            rc = av_interleaved_write_frame(format, packet);  // takes the packet's data either way
            if (rc < 0) throw write_failed(path, av_error(rc));
        }
    }
};

VideoWriter::VideoWriter() = default;

VideoWriter::~VideoWriter() {
    try {
        finish();
    } catch (...) {  // a destructor must not throw; finish() is the way to hear of it
    }
}

void VideoWriter::open(const std::string& path, int width, int height, double fps, VideoCodec choice) {
    if (impl_ && !impl_->finished)
        throw std::logic_error("VideoWriter::open: '" + impl_->path + "' is still open");
    if (path.empty()) throw std::runtime_error("cannot write video: the path is empty");
    if (width <= 0 || height <= 0)
        throw cannot_write(path, fmt::format("the picture size {}x{} is empty", width, height));
    if (width % 2 != 0 || height % 2 != 0)
        throw cannot_write(path, fmt::format("the picture size {}x{} is odd; yuv420p video (what players "
                                             "show) needs an even width and height",
                                             width, height));
    if (!(fps >= 1 && fps <= kMaxFps))
        throw cannot_write(path, fmt::format("{} frames per second is outside [1, {}]", fps, kMaxFps));

    auto s = std::make_unique<Impl>();
    s->path = path;
    s->width = width, s->height = height;
    s->rate = video_frame_rate(fps);

    const std::string extension = std::filesystem::path(path).extension().string();
    if (extension.empty() || extension == ".")
        throw cannot_write(path,
                           "the name has no extension to choose a container by (.mp4, .mkv, .mov, .avi)");
    int rc = avformat_alloc_output_context2(&s->format, nullptr, nullptr, path.c_str());
    if (rc < 0 || !s->format)
        throw cannot_write(
            path, fmt::format("no container is known for '{}' (use .mp4, .mkv, .mov or .avi)", extension));
    const AVOutputFormat* container = s->format->oformat;
    // Such formats write elsewhere than the one file (image2: a numbered picture per frame; null, RTP).
    if (container->flags & AVFMT_NOFILE)
        throw cannot_write(path,
                           fmt::format("the '{}' format writes no single video file (use .mp4, .mkv, .mov "
                                       "or .avi; --out writes PNG frames)",
                                       container->name));
    if (container->video_codec == AV_CODEC_ID_NONE)
        throw cannot_write(path, fmt::format("the '{}' container holds no video", container->name));
    const AVCodec* encoder = pick_encoder(container, choice);
    if (!encoder)
        throw cannot_write(path, fmt::format("the '{}' container takes neither H.264 nor MPEG-4 part 2 video "
                                             "(use .mp4, .mkv, .mov or .avi)",
                                             container->name));
    const bool h264 = encoder->id == AV_CODEC_ID_H264;
    s->codec_name = encoder->name;
    s->codec_description = fmt::format("{} ({})", h264 ? "H.264" : "MPEG-4 part 2", encoder->name);

    s->codec = avcodec_alloc_context3(encoder);
    s->frame = av_frame_alloc();
    s->packet = av_packet_alloc();
    if (!s->codec || !s->frame || !s->packet) throw cannot_write(path, "out of memory");
    AVCodecContext& c = *s->codec;
    c.width = width;
    c.height = height;
    c.pix_fmt = AV_PIX_FMT_YUV420P;
    c.framerate = {s->rate.num, s->rate.den};
    c.time_base = {s->rate.den, s->rate.num};
    // Rendered pictures are sRGB-like display values; BT.709 is what players assume for HD and what the
    // conversion below uses, so tagging it keeps the colours where they were.
    c.color_range = AVCOL_RANGE_MPEG;
    c.colorspace = AVCOL_SPC_BT709;
    c.color_primaries = AVCOL_PRI_BT709;
    c.color_trc = AVCOL_TRC_BT709;
    // One encoder thread: x264 and mpeg4 then give the same bytes every run, and --threads stays a bound.
    c.thread_count = 1;
    c.flags |= AV_CODEC_FLAG_BITEXACT;  // no library version strings in the stream
    if (h264) {
        // CRF 20 looks clean on smooth shaded water; veryfast keeps a 720p frame near its PNG's cost.
        av_opt_set(c.priv_data, "preset", "veryfast", 0);
        av_opt_set(c.priv_data, "crf", "20", 0);
    } else {
        // Constant quantizer 3 (1 best, 31 worst): no visible blocks, about 5x the H.264 file size.
        c.flags |= AV_CODEC_FLAG_QSCALE;
        c.global_quality = FF_QP2LAMBDA * 3;
    }
    if (container->flags & AVFMT_GLOBALHEADER) c.flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    rc = avcodec_open2(s->codec, encoder, nullptr);
    if (rc < 0)
        throw cannot_write(path, fmt::format("the {} encoder refused {}x{} at {}/{} fps: {}", encoder->name,
                                             width, height, s->rate.num, s->rate.den, av_error(rc)));

    s->stream = avformat_new_stream(s->format, nullptr);
    if (!s->stream) throw cannot_write(path, "out of memory");
    s->stream->time_base = c.time_base;
    s->stream->avg_frame_rate = c.framerate;
    rc = avcodec_parameters_from_context(s->stream->codecpar, s->codec);
    if (rc < 0) throw cannot_write(path, av_error(rc));
    s->format->flags |= AVFMT_FLAG_BITEXACT;

    s->frame->format = AV_PIX_FMT_YUV420P;
    s->frame->width = width;
    s->frame->height = height;
    rc = av_frame_get_buffer(s->frame, 0);
    if (rc < 0) throw cannot_write(path, av_error(rc));
    // Bit-exact so the bytes do not depend on which SIMD path this CPU takes.
    s->sws = sws_getContext(width, height, AV_PIX_FMT_RGBA, width, height, AV_PIX_FMT_YUV420P,
                            SWS_BILINEAR | SWS_ACCURATE_RND | SWS_BITEXACT, nullptr, nullptr, nullptr);
    if (!s->sws) throw cannot_write(path, "no RGBA to yuv420p conversion");
    const int* bt709 = sws_getCoefficients(SWS_CS_ITU709);
    sws_setColorspaceDetails(s->sws, bt709, 1, bt709, 0, 0, 1 << 16, 1 << 16);

    rc = avio_open(&s->format->pb, path.c_str(), AVIO_FLAG_WRITE);
    if (rc < 0) throw cannot_write(path, av_error(rc));
    s->file_open = true;
    rc = avformat_write_header(s->format, nullptr);
    if (rc < 0) {
        s->release();
        std::error_code ignored;
        std::filesystem::remove(path, ignored);
        throw cannot_write(path, fmt::format("the '{}' container refused the {} stream: {}", container->name,
                                             encoder->name, av_error(rc)));
    }
    impl_ = std::move(s);
}

void VideoWriter::write(std::span<const std::uint8_t> rgba) {
    if (!is_open()) throw std::logic_error("VideoWriter::write: no video is open");
    Impl& s = *impl_;
    const std::size_t bytes = std::size_t(s.width) * std::size_t(s.height) * 4u;
    if (rgba.size() != bytes)
        throw std::invalid_argument(fmt::format("video '{}': a frame has {} bytes, a {}x{} RGBA picture {}",
                                                s.path, rgba.size(), s.width, s.height, bytes));
    // The encoder may still hold the previous frame's planes (reference frames); then this gives new ones.
    int rc = av_frame_make_writable(s.frame);
    if (rc < 0) throw write_failed(s.path, av_error(rc));
    const std::uint8_t* const src[1] = {rgba.data()};
    const int src_stride[1] = {s.width * 4};
    sws_scale(s.sws, src, src_stride, 0, s.height, s.frame->data, s.frame->linesize);
    s.frame->pts = s.frames;
    if (s.codec->flags & AV_CODEC_FLAG_QSCALE) s.frame->quality = s.codec->global_quality;
    s.encode(s.frame);
    ++s.frames;
}

void VideoWriter::finish() {
    if (!is_open()) return;
    Impl& s = *impl_;
    s.finished = true;  // first: a failure below is reported once, not again by the destructor
    try {
        s.encode(nullptr);
        int rc = av_write_trailer(s.format);
        if (rc < 0) throw write_failed(s.path, av_error(rc));
        if (s.file_open) {
            s.file_open = false;
            rc = avio_closep(&s.format->pb);
            if (rc < 0) throw write_failed(s.path, av_error(rc));
        }
    } catch (...) {
        s.release();
        throw;
    }
    s.release();
}

bool VideoWriter::is_open() const {
    return impl_ && !impl_->finished;
}

namespace {
const std::string kNone;
}

const std::string& VideoWriter::path() const {
    return impl_ ? impl_->path : kNone;
}
int VideoWriter::width() const {
    return impl_ ? impl_->width : 0;
}
int VideoWriter::height() const {
    return impl_ ? impl_->height : 0;
}
VideoFrameRate VideoWriter::frame_rate() const {
    return impl_ ? impl_->rate : VideoFrameRate{};
}
const std::string& VideoWriter::codec_name() const {
    return impl_ ? impl_->codec_name : kNone;
}
const std::string& VideoWriter::codec_description() const {
    return impl_ ? impl_->codec_description : kNone;
}
std::int64_t VideoWriter::frames() const {
    return impl_ ? impl_->frames : 0;
}

void silence_video_library_log() {
    av_log_set_level(AV_LOG_QUIET);
}

}  // namespace rivulet
