#include "jobs/cell_radix_sort.h"

#include <algorithm>
#include <bit>
#include <utility>

#include "jobs/grid_links.h"

namespace rivulet {

void cell_radix_sort(const CellSortBuffers& b, std::uint32_t max_index_x, std::uint32_t max_index_y,
                     std::uint32_t max_index_z) {
    const std::size_t n = b.key.size();
    for (std::size_t i = 0; i < n; ++i) b.order[i] = static_cast<std::uint32_t>(i);
    std::uint64_t *key = b.key.data(), *key_out = b.key_tmp.data();
    std::uint32_t *order = b.order.data(), *order_out = b.order_tmp.data();
    const std::uint32_t max_index[3] = {max_index_x, max_index_y, max_index_z};
    for (int field = 0; field < 3; ++field) {
        const auto bits = static_cast<std::uint32_t>(std::bit_width(max_index[field]));
        for (std::uint32_t low = 0; low < bits; low += 11) {
            const std::uint32_t shift = std::uint32_t(field) * kCellKeyBits + low;
            const std::uint32_t width = std::min(11u, bits - low);
            const std::uint64_t mask = (std::uint64_t{1} << width) - 1;
            const std::span<std::uint32_t> counts = b.counts.first(std::size_t{1} << width);
            std::fill(counts.begin(), counts.end(), 0u);
            for (std::size_t i = 0; i < n; ++i) ++counts[(key[i] >> shift) & mask];
            std::uint32_t sum = 0;
            for (std::uint32_t& c : counts) sum += std::exchange(c, sum);
            for (std::size_t i = 0; i < n; ++i) {
                const std::uint32_t at = counts[(key[i] >> shift) & mask]++;
                key_out[at] = key[i], order_out[at] = order[i];
            }
            std::swap(key, key_out), std::swap(order, order_out);
        }
    }
    if (key != b.key.data()) {
        std::copy_n(key, n, b.key.data());
        std::copy_n(order, n, b.order.data());
    }
}

}  // namespace rivulet
