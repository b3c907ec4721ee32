#pragma once
// Sanity limits for counts read from file headers: a corrupt or hostile header must not make us reserve
// gigabytes before the data has been seen.
#include <cstddef>
#include <cstdint>

namespace rivulet::io {

inline constexpr std::uint64_t kMaxElementCount = 500'000'000;

// Header lines are short; a longer "line" means we are looking at binary data, not a header.
inline constexpr std::size_t kMaxHeaderLine = 64 * 1024;

// Data lines (ascii PLY, xyz, obj) stay well under this; the cap keeps a newline-free file from being
// buffered whole.
inline constexpr std::size_t kMaxDataLine = 1024 * 1024;

}  // namespace rivulet::io
