#pragma once
// Buffered reading of one input file for the format readers: lines for headers and text bodies, bulk
// bytes for binary bodies, and the file size up front so binary readers can check a declared count
// against the bytes actually present before allocating anything.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace rivulet::io {

class InputFile {
  public:
    // Throws FileFormatError (with the system's reason) if the path cannot be opened, is not a regular
    // file, or is empty.
    explicit InputFile(std::string path);

    const std::string& path() const { return path_; }
    std::uint64_t size() const { return size_; }
    std::uint64_t remaining() const { return consumed_ >= size_ ? 0 : size_ - consumed_; }
    // 1-based number of the line most recently returned by read_line.
    std::uint64_t line_number() const { return line_; }

    // Next line without its "\n" or "\r\n"; false only when nothing is left. A line longer than
    // `max_length` is an error, so a newline-free binary file is never buffered whole.
    bool read_line(std::string& line, std::size_t max_length);
    // Up to `n` bytes; fewer only at end of file.
    std::size_t read(std::byte* dst, std::size_t n);
    // Skips up to `n` bytes; returns how many were skipped.
    std::uint64_t skip(std::uint64_t n);

    // Text formats are parsed value by value; beyond kMaxTextFileBytes (io_limits.h) this fails with a
    // message naming `format`, the file's size and the limit.
    void require_text_size(std::string_view format) const;

    [[noreturn]] void fail(std::string_view what) const;
    [[noreturn]] void fail_at_line(std::uint64_t line, std::string_view what) const;

  private:
    struct Closer {
        void operator()(std::FILE* f) const { std::fclose(f); }
    };
    bool fill();

    std::string path_;
    std::unique_ptr<std::FILE, Closer> file_;
    std::uint64_t size_ = 0;
    std::uint64_t consumed_ = 0;
    std::uint64_t line_ = 0;
    std::vector<char> buffer_;
    std::size_t begin_ = 0, end_ = 0;
};

// Reason text for errno, safe to call from several reader threads at once (unlike strerror).
std::string errno_message(int err);

}  // namespace rivulet::io
