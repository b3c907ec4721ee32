#include "systems/io/input_file.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <system_error>

#include "systems/io/file_format_error.h"
#include "systems/io/io_limits.h"
#include "systems/io/text_parse.h"

namespace rivulet::io {

std::string errno_message(int err) {
    return std::error_code(err, std::generic_category()).message();
}

namespace {
constexpr std::uint64_t kBufferBytes = 64 * 1024;
}  // namespace

InputFile::InputFile(std::string path) : path_(std::move(path)) {
    file_.reset(std::fopen(path_.c_str(), "rb"));
    if (!file_) fail("cannot open: " + errno_message(errno));
    struct stat st {};
    if (::fstat(::fileno(file_.get()), &st) != 0) fail("cannot stat: " + errno_message(errno));
    if (S_ISDIR(st.st_mode)) fail("cannot read: " + errno_message(EISDIR));
    // Pipes and devices have no size to check declared counts against.
    if (!S_ISREG(st.st_mode)) fail("cannot read: not a regular file");
    if (st.st_size == 0) fail("file is empty");
    size_ = static_cast<std::uint64_t>(st.st_size);
    // A small file gets a buffer of its own size: readers open many small files (a scene, a sequence
    // of frames, a fuzzer's millions of inputs), and each would otherwise allocate and zero 64 KiB.
    buffer_.resize(static_cast<std::size_t>(std::min(size_, kBufferBytes)));
}

bool InputFile::fill() {
    begin_ = 0;
    end_ = std::fread(buffer_.data(), 1, buffer_.size(), file_.get());
    if (end_ == 0 && std::ferror(file_.get())) fail("read error: " + errno_message(errno));
    return end_ > 0;
}

bool InputFile::read_line(std::string& line, std::size_t max_length) {
    line.clear();
    bool any = false;
    for (;;) {
        if (begin_ == end_ && !fill()) break;
        any = true;
        const char* start = buffer_.data() + begin_;
        const auto* nl = static_cast<const char*>(std::memchr(start, '\n', end_ - begin_));
        const std::size_t take = nl ? static_cast<std::size_t>(nl - start) : end_ - begin_;
        if (line.size() + take > max_length) {
            fail_at_line(line_ + 1, "line is longer than " + std::to_string(max_length) +
                                        " bytes (binary data where text was expected?)");
        }
        line.append(start, take);
        begin_ += take;
        consumed_ += take;
        if (nl) {
            ++begin_;
            ++consumed_;
            break;
        }
    }
    if (!any) return false;
    ++line_;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return true;
}

std::size_t InputFile::read(std::byte* dst, std::size_t n) {
    if (n == 0) return 0;
    std::size_t got = std::min(n, end_ - begin_);
    std::memcpy(dst, buffer_.data() + begin_, got);
    begin_ += got;
    while (got < n) {
        const std::size_t r = std::fread(dst + got, 1, n - got, file_.get());
        if (r == 0) {
            if (std::ferror(file_.get())) fail("read error: " + errno_message(errno));
            break;
        }
        got += r;
    }
    consumed_ += got;
    return got;
}

std::uint64_t InputFile::skip(std::uint64_t n) {
    std::uint64_t done = 0;
    while (done < n) {
        if (begin_ == end_ && !fill()) break;
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(n - done, end_ - begin_));
        begin_ += take;
        done += take;
    }
    consumed_ += done;
    return done;
}

void InputFile::require_text_size(std::string_view format) const {
    if (size_ <= kMaxTextFileBytes) return;
    fail(std::string(format) + " file of " + std::to_string(size_) + " bytes is over the " +
         bytes_text(kMaxTextFileBytes) +
         " limit for text formats (XYZ, ASCII PLY, ASCII VTK, OBJ); convert it to binary PLY");
}

void InputFile::fail(std::string_view what) const {
    throw FileFormatError(path_ + ": " + std::string(what));
}

void InputFile::fail_at_line(std::uint64_t line, std::string_view what) const {
    fail("line " + std::to_string(line) + ": " + std::string(what));
}

}  // namespace rivulet::io
