#include <charconv>
#include <string>

#include "systems/io/mesh_formats.h"
#include "systems/io/output_file.h"

namespace rivulet::io {
namespace {

// Text is built in a reused buffer and handed over in large pieces; std::to_chars gives the shortest
// text that parses back to the same float, so OBJ round trips are exact.
class ObjText {
  public:
    explicit ObjText(OutputFile& out) : out_(out) { text_.reserve(kFlushAt + 256); }
    void line(const char* tag, float a, float b, float c) {
        text_ += tag;
        for (float v : {a, b, c}) {
            text_ += ' ';
            append(v);
        }
        end_line();
    }
    void face(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        text_ += 'f';
        for (std::uint32_t i : {a, b, c}) {
            text_ += ' ';
            append(i + std::uint64_t{1});
            text_ += "//";
            append(i + std::uint64_t{1});
        }
        end_line();
    }
    void finish() {
        out_.write(text_);
        text_.clear();
    }

  private:
    static constexpr std::size_t kFlushAt = OutputFile::kBufferBytes;  // hands stdio a full buffer
    template <class T>
    void append(T v) {
        char buf[32];
        const auto r = std::to_chars(buf, buf + sizeof buf, v);
        text_.append(buf, r.ptr);
    }
    void end_line() {
        text_ += '\n';
        if (text_.size() >= kFlushAt) finish();
    }
    OutputFile& out_;
    std::string text_;
};

}  // namespace

void write_obj_mesh(const std::string& path, std::span<const float> v6, std::span<const std::uint32_t> idx) {
    OutputFile out(path);
    ObjText text(out);
    out.write("# written by Rivulet: " + std::to_string(v6.size() / 6) + " vertices, " +
              std::to_string(idx.size() / 3) + " triangles\n");
    for (std::size_t i = 0; i < v6.size(); i += 6) text.line("v", v6[i], v6[i + 1], v6[i + 2]);
    for (std::size_t i = 0; i < v6.size(); i += 6) text.line("vn", v6[i + 3], v6[i + 4], v6[i + 5]);
    for (std::size_t t = 0; t < idx.size(); t += 3) text.face(idx[t], idx[t + 1], idx[t + 2]);
    text.finish();
    out.commit();
}

}  // namespace rivulet::io
