#pragma once
// Sanity limits for what a file may make us allocate or loop over (docs/limits.md lists them all): a
// corrupt or hostile file must not make us reserve gigabytes before the data has been seen, nor read
// an endless stream until memory runs out.
#include <cstddef>
#include <cstdint>

namespace rivulet::io {

inline constexpr std::uint64_t kMaxElementCount = 500'000'000;

// Header lines are short; a longer "line" means we are looking at binary data, not a header.
inline constexpr std::size_t kMaxHeaderLine = 64 * 1024;

// Data lines (ascii PLY, xyz, obj) stay well under this; the cap keeps a newline-free file from being
// buffered whole.
inline constexpr std::size_t kMaxDataLine = 1024 * 1024;

// Text particle and mesh files (XYZ, ASCII PLY, ASCII VTK, OBJ). Parsing text costs about 20x reading
// binary, and a cloud this size already holds ~100 M particles: larger data belongs in binary PLY.
inline constexpr std::uint64_t kMaxTextFileBytes = std::uint64_t{2} << 30;

// JSON documents are parsed whole into a DOM several times their size, so each kind has its own cap,
// a generous multiple of the largest valid document Rivulet writes or reads of that kind.
inline constexpr std::uint64_t kMaxSceneFileBytes = std::uint64_t{16} << 20;   // scenes: a few KB
inline constexpr std::uint64_t kMaxRecordingBytes = std::uint64_t{512} << 20;  // 2 M frames ~ 250 MB
inline constexpr std::uint64_t kMaxTraceFileBytes = std::uint64_t{1} << 30;    // 1 M zones ~ 200 MB
inline constexpr std::uint64_t kMaxReportFileBytes = std::uint64_t{64} << 20;  // bench case reports

}  // namespace rivulet::io
