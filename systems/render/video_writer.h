#pragma once
// Encodes RGBA8 pictures (rows top to bottom) into a video file with FFmpeg's libraries (docs/video.md):
// H.264 through libx264 where libavcodec has it, else MPEG-4 part 2, in yuv420p so every player shows it.
// The container follows the file's extension (.mp4, .mkv, .mov, .avi, ...). One encoder thread: the
// bytes depend only on the pictures and the frame rate, and the caller's thread budget holds.
#include <cstdint>
#include <memory>
#include <span>
#include <string>

namespace rivulet {

// A frame rate as the exact fraction the container stores (60/1, 30000/1001, 100/3).
struct VideoFrameRate {
    int num = 0, den = 1;
    double fps() const { return den > 0 ? double(num) / double(den) : 0.0; }
};

// The simplest fraction within float precision of `fps` (a scene's 1/dt, where dt is a float): 1/(1/60.f)
// becomes 60/1, not 59999/1000. Throws std::invalid_argument unless fps is finite and positive.
VideoFrameRate video_frame_rate(double fps);

enum class VideoCodec {
    kAuto,   // H.264 (libx264) where present and the container takes it, else MPEG-4 part 2
    kMpeg4,  // MPEG-4 part 2 even where libx264 is present (tests of the fallback)
};

class VideoWriter {
  public:
    // Players and the MPEG-4 part 2 time base (16 bits) both stop well above this; no scene needs more.
    static constexpr double kMaxFps = 1000;

    VideoWriter();
    // Finishes an open video quietly (a failure then is lost; call finish() to hear of it).
    ~VideoWriter();
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    // Creates `path` for width x height pictures at `fps` frames per second and writes its header.
    // Throws std::runtime_error naming the path when the size is empty or odd (yuv420p halves both),
    // fps is outside [1, kMaxFps], no container knows the extension or takes H.264/MPEG-4 video, or the
    // file cannot be created; nothing is left behind then.
    void open(const std::string& path, int width, int height, double fps,
              VideoCodec codec = VideoCodec::kAuto);
    // Encodes the next frame: width*height*4 bytes. Throws std::invalid_argument on another size,
    // std::logic_error when not open, std::runtime_error when the file cannot be written.
    void write(std::span<const std::uint8_t> rgba);
    // Drains the encoder and writes the trailer; the file is complete after it. Throws std::runtime_error
    // on a write failure. Does nothing when not open; the accessors below keep their values.
    void finish();

    bool is_open() const;
    const std::string& path() const;
    int width() const;
    int height() const;
    VideoFrameRate frame_rate() const;
    // The encoder's name, "libx264" or "mpeg4", and a description for people ("H.264 (libx264)").
    const std::string& codec_name() const;
    const std::string& codec_description() const;
    std::int64_t frames() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// libav* print their own notes (x264's settings and statistics, muxer warnings) on stderr; commands whose
// errors must be one `rivulet: error:` line call this once. Process-wide, so the library leaves it to them.
void silence_video_library_log();

}  // namespace rivulet
