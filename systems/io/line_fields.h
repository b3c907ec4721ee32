#pragma once
// Text bodies as a sequence of non-blank lines split into fields, with the line number kept for errors.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "systems/io/input_file.h"

namespace rivulet::io {

class LineFields {
  public:
    explicit LineFields(InputFile& in) : in_(in) {}

    // Advances to the next line holding anything but whitespace; false at end of file.
    bool next();
    std::span<const std::string_view> fields() const { return fields_; }
    std::uint64_t line() const { return in_.line_number(); }
    [[noreturn]] void fail(std::string_view what) const { in_.fail_at_line(line(), what); }

  private:
    InputFile& in_;
    std::string text_;
    std::vector<std::string_view> fields_;
};

}  // namespace rivulet::io
