#include "systems/io/output_file.h"

#include <sys/stat.h>

#include <cerrno>

#include "systems/io/file_format_error.h"
#include "systems/io/input_file.h"

namespace rivulet::io {

OutputFile::OutputFile(std::string path) : path_(std::move(path)) {
    file_ = std::fopen(path_.c_str(), "wb");
    if (!file_) fail("cannot open for writing: " + errno_message(errno));
    struct stat st {};
    regular_ = ::fstat(::fileno(file_), &st) == 0 && S_ISREG(st.st_mode);
    // The writers emit many small pieces and the default BUFSIZ costs a syscall per 8 KiB; beyond 64 KiB
    // a syscall costs nothing measurable, while a larger buffer is a fresh mapping for every small file.
    std::setvbuf(file_, nullptr, _IOFBF, kBufferBytes);
}

OutputFile::~OutputFile() {
    discard();
}

void OutputFile::discard() noexcept {
    if (!file_) return;
    std::fclose(file_);
    file_ = nullptr;
    if (regular_) std::remove(path_.c_str());
}

void OutputFile::write(const void* data, std::size_t n) {
    if (n == 0) return;
    if (std::fwrite(data, 1, n, file_) != n) {
        const int err = errno;
        discard();
        fail("write failed: " + errno_message(err));
    }
}

void OutputFile::commit() {
    const bool flushed = std::fflush(file_) == 0 && !std::ferror(file_);
    const int flush_err = errno;
    if (!flushed) {
        discard();
        fail("write failed: " + errno_message(flush_err));
    }
    std::FILE* f = file_;
    file_ = nullptr;
    if (std::fclose(f) != 0) {
        const int err = errno;
        if (regular_) std::remove(path_.c_str());
        fail("write failed on close: " + errno_message(err));
    }
}

void write_text_file(const std::string& path, std::string_view text) {
    OutputFile out(path);
    out.write(text);
    out.commit();
}

void OutputFile::fail(std::string_view what) const {
    throw FileFormatError(path_ + ": " + std::string(what));
}

}  // namespace rivulet::io
