#include "jobs/grid_links.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rivulet {
namespace {
constexpr std::uint32_t kMaxReach = 3;
}  // namespace

std::size_t grid_link_pairs(ConstPositions p, std::span<const std::uint64_t> key, std::uint32_t reach,
                            float link, std::span<std::uint32_t> pair_a, std::span<std::uint32_t> pair_b,
                            std::span<float> pair_length) {
    if (reach < 1 || reach > kMaxReach)
        throw std::invalid_argument("grid_link_pairs: reach must be in [1, 3], got " + std::to_string(reach));
    const auto n = static_cast<std::uint32_t>(key.size());
    const float link2 = link * link;
    const auto r = static_cast<std::int64_t>(reach);
    // The rows after a point's own: (0, 1 .. r), then (1 .. r, -r .. r).
    constexpr std::uint32_t kMaxRows = kMaxReach + kMaxReach * (2 * kMaxReach + 1);
    std::int64_t row_offset[kMaxRows];
    std::uint32_t cursor[kMaxRows] = {}, rows = 0;
    for (std::int64_t dz = 0; dz <= r; ++dz)
        for (std::int64_t dy = dz == 0 ? 1 : -r; dy <= r; ++dy)
            row_offset[rows++] =
                dz * (std::int64_t{1} << (2 * kCellKeyBits)) + dy * (std::int64_t{1} << kCellKeyBits);
    std::size_t pairs = 0;
    const auto test = [&](std::uint32_t a, std::uint32_t b) {
        const float dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
        const float d2 = dx * dx + dy * dy + dz * dz;
        if (!(d2 < link2)) return;
        if (pairs < pair_a.size()) pair_a[pairs] = a, pair_b[pairs] = b, pair_length[pairs] = std::sqrt(d2);
        ++pairs;
    };
    for (std::uint32_t a = 0; a < n; ++a) {
        const std::uint64_t k = key[a];
        for (std::uint32_t b = a + 1; b < n && key[b] <= k + reach; ++b) test(a, b);
        for (std::uint32_t row = 0; row < rows; ++row) {
            const std::uint64_t centre = k + static_cast<std::uint64_t>(row_offset[row]);
            std::uint32_t& c = cursor[row];
            while (c < n && key[c] < centre - reach) ++c;
            for (std::uint32_t b = c; b < n && key[b] <= centre + reach; ++b) test(a, b);
        }
    }
    return pairs;
}

void link_rows(std::span<const std::uint32_t> pair_a, std::span<const std::uint32_t> pair_b,
               std::span<const float> pair_length, std::span<std::uint32_t> first,
               std::span<std::uint32_t> to, std::span<float> length) {
    std::fill(first.begin(), first.end(), 0u);
    for (std::size_t e = 0; e < pair_a.size(); ++e) ++first[pair_a[e] + 1], ++first[pair_b[e] + 1];
    for (std::size_t i = 1; i < first.size(); ++i) first[i] += first[i - 1];
    // Scatter with first[i] as point i's cursor, then shift the rows' starts back.
    for (std::size_t e = 0; e < pair_a.size(); ++e) {
        const std::uint32_t at_a = first[pair_a[e]]++, at_b = first[pair_b[e]]++;
        to[at_a] = pair_b[e], length[at_a] = pair_length[e];
        to[at_b] = pair_a[e], length[at_b] = pair_length[e];
    }
    for (std::size_t i = first.size() - 1; i > 0; --i) first[i] = first[i - 1];
    first[0] = 0;
}

}  // namespace rivulet
