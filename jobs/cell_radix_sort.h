#pragma once
// Points sorted by the cell they fall in (keys from pack_cell_key, jobs/grid_links.h), in linear time:
// a stable LSD radix sort over only the bits the keys use, at most 11 bits a pass (a 2,048-slot
// histogram that stays in L1), each field split into as few passes as its highest index needs. Cells
// of a scene a thousand cells across take three passes; ties keep index order, so the result is the
// same bytes every run.
#include <cstdint>
#include <span>

namespace rivulet {

inline constexpr std::uint32_t kCellSortDigits = 2048;

struct CellSortBuffers {
    std::span<std::uint64_t> key, key_tmp;      // n each; `key` holds the keys on entry
    std::span<std::uint32_t> order, order_tmp;  // n each
    std::span<std::uint32_t> counts;            // kCellSortDigits
};

// Sorts points 0 .. n-1 by key; `max_index` is the highest cell index of any field (x, y, z). On return
// `order` holds the points in key order and `key` their keys in that order.
void cell_radix_sort(const CellSortBuffers& b, std::uint32_t max_index_x, std::uint32_t max_index_y,
                     std::uint32_t max_index_z);

}  // namespace rivulet
