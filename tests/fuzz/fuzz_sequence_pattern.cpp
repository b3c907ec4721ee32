// Frame-sequence patterns ("frame_{}.ply"). The input is text: the first line is a pattern, every further
// line the name of a file to create beside it. Whatever expand_sequence returns must be sorted by frame
// number, and sequence_output_path must give each frame's own path back from its number and width.
#include <filesystem>
#include <string_view>
#include <vector>

#include "systems/io/sequence_pattern.h"
#include "tests/fuzz/harness.h"

namespace {

constexpr std::size_t kMaxFiles = 32;

std::vector<std::string_view> lines_of(std::string_view text) {
    std::vector<std::string_view> lines;
    while (!text.empty()) {
        const std::size_t end = text.find('\n');
        lines.push_back(text.substr(0, end));
        if (end == std::string_view::npos) break;
        text.remove_prefix(end + 1);
    }
    return lines;
}

// A name for one file in the folder: no separator, no NUL, not "." or "..".
bool plain_name(std::string_view name) {
    return !name.empty() && name != "." && name != ".." && name.size() <= 200 &&
           name.find_first_of(std::string_view("/\0", 2)) == std::string_view::npos;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<std::string_view> lines =
        lines_of(std::string_view(reinterpret_cast<const char*>(data), size));
    // ".." could list folders outside the scratch one, whose contents change under the fuzzer.
    if (lines.empty() || lines[0].find('\0') != std::string_view::npos ||
        lines[0].find("..") != std::string_view::npos)
        return 0;

    const std::string dir = rivulet::fuzz::scratch_dir() + "/seq";
    std::error_code ec;
    std::filesystem::remove_all(dir, ec);
    std::filesystem::create_directory(dir, ec);
    if (ec) rivulet::fuzz::finding("cannot create " + dir + ": " + ec.message());
    for (std::size_t i = 1; i < lines.size() && i <= kMaxFiles; ++i) {
        if (plain_name(lines[i])) rivulet::fuzz::write_scratch("seq/" + std::string(lines[i]), data, 0);
    }

    const std::string pattern = dir + "/" + std::string(lines[0]);
    (void)rivulet::is_sequence_pattern(pattern);
    const auto frames = rivulet::fuzz::read_or_reject([&] { return rivulet::expand_sequence(pattern); });
    if (!frames) return 0;
    for (std::size_t i = 0; i < frames->size(); ++i) {
        const rivulet::SequenceFrame& f = (*frames)[i];
        if (i > 0 && (*frames)[i - 1].number >= f.number)
            rivulet::fuzz::finding("expand_sequence: frames out of order at " + f.path);
        const std::string back = rivulet::sequence_output_path(pattern, f.number, f.width);
        if (back != f.path)
            rivulet::fuzz::finding("sequence_output_path gives " + back + " for frame " + f.path);
    }
    return 0;
}
