#pragma once
// Frame sequences named by a pattern with one "{}" placeholder for the frame number, e.g.
// "frames/frame_{}.ply" matches frames/frame_7.ply and frames/frame_0007.ply.
#include <cstdint>
#include <string>
#include <vector>

#include "systems/io/file_format_error.h"

namespace rivulet {

struct SequenceFrame {
    std::int64_t number = 0;
    std::string path;
    int width = 0;  // digits in the matched name, zero padding included ("0007" -> 4)
};

// Every existing regular file whose name is the pattern with "{}" replaced by a run of decimal digits,
// sorted by number. The placeholder must be in the file name, not in a directory. Throws
// FileFormatError if the pattern has no or several "{}", nothing matches, or two files carry the same
// number (frame_7 and frame_07).
std::vector<SequenceFrame> expand_sequence(const std::string& pattern);

// True if `s` contains "{}" (malformed patterns with several are reported by expand_sequence).
bool is_sequence_pattern(const std::string& s);

// "out_{}.obj", 7, 4 -> "out_0007.obj"; pad_width <= 0 means no padding. Throws FileFormatError unless
// the pattern has exactly one "{}".
std::string sequence_output_path(const std::string& out_pattern, std::int64_t number, int pad_width);

}  // namespace rivulet
