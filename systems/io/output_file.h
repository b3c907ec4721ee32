#pragma once
// Output file for the writers. Write failures (disk full, I/O error) surface as FileFormatError at the
// latest in commit(), which checks the close; a file that was never committed is removed so a failed
// write leaves no truncated file that a later run could mistake for a finished frame.
#include <cstddef>
#include <cstdio>
#include <string>
#include <string_view>

namespace rivulet::io {

class OutputFile {
  public:
    // The stdio buffer: writes of about this size or more are as cheap as any larger.
    static constexpr std::size_t kBufferBytes = 64 * 1024;

    explicit OutputFile(std::string path);
    ~OutputFile();
    OutputFile(const OutputFile&) = delete;
    OutputFile& operator=(const OutputFile&) = delete;

    void write(const void* data, std::size_t n);
    void write(std::string_view text) { write(text.data(), text.size()); }
    // Flushes and closes; throws if any byte did not reach the file.
    void commit();

    [[noreturn]] void fail(std::string_view what) const;

  private:
    void discard() noexcept;

    std::string path_;
    std::FILE* file_ = nullptr;
    bool regular_ = false;  // only regular files are removed on failure, never a device or pipe
};

// The whole of `text` as the file's content (reports, JSON, scripts): an OutputFile written and
// committed, so a failure throws FileFormatError naming the path and leaves no partial file.
void write_text_file(const std::string& path, std::string_view text);

}  // namespace rivulet::io
