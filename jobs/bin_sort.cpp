#include "jobs/bin_sort.h"

#include <cmath>

namespace rivulet {

bool BinGrid::span_of(float y, std::uint32_t& first, std::uint32_t& last) const {
    // Plane b is hit when |y - plane_y(b)| <= radius, i.e. b in [(top - y - r) / s, (top - y + r) / s].
    // One reciprocal instead of two divisions: the loops that call this hoist it.
    const float inv_spacing = 1.0f / spacing;
    const float lo = std::ceil((top - y - radius) * inv_spacing);
    const float hi = std::floor((top - y + radius) * inv_spacing);
    const float max_bin = static_cast<float>(bins) - 1.0f;
    if (!(hi >= 0.0f) || !(lo <= max_bin) || hi < lo) return false;
    first = static_cast<std::uint32_t>(lo < 0.0f ? 0.0f : lo);
    last = static_cast<std::uint32_t>(hi > max_bin ? max_bin : hi);
    return true;
}

std::uint32_t BinGrid::max_bins_per_particle() const {
    return static_cast<std::uint32_t>(std::floor(2.0f * radius / spacing)) + 2u;
}

void bin_count_chunk(const BinGrid& grid, std::span<const float> y, std::span<std::uint32_t> counts,
                     const ParticleBins& spans) {
    for (auto& c : counts) c = 0;
    std::uint32_t first = 0, last = 0;
    for (std::size_t i = 0; i < y.size(); ++i) {
        if (!grid.span_of(y[i], first, last)) {
            spans.first[i] = spans.end[i] = 0;
            continue;
        }
        spans.first[i] = first, spans.end[i] = last + 1;
        for (std::uint32_t b = first; b <= last; ++b) ++counts[b];
    }
}

std::uint32_t bin_prefix(std::uint32_t bins, std::uint32_t chunks, std::span<const std::uint32_t> counts,
                         std::span<std::uint32_t> cursors, std::span<std::uint32_t> offsets) {
    std::uint32_t running = 0;
    for (std::uint32_t b = 0; b < bins; ++b) {
        offsets[b] = running;
        for (std::uint32_t c = 0; c < chunks; ++c) {
            cursors[std::size_t(c) * bins + b] = running;
            running += counts[std::size_t(c) * bins + b];
        }
    }
    offsets[bins] = running;
    return running;
}

void bin_scatter_chunk(ConstPositions p, std::uint32_t first_index, const ParticleBins& spans,
                       std::span<std::uint32_t> cursors, const BinEntriesOut& out) {
    for (std::uint32_t i = 0; i < p.size(); ++i) {
        for (std::uint32_t b = spans.first[i]; b < spans.end[i]; ++b) {
            const std::uint32_t e = cursors[b]++;
            out.entries[e] = first_index + i;
            out.ex[e] = p.x[i], out.ey[e] = p.y[i], out.ez[e] = p.z[i];
        }
    }
}

}  // namespace rivulet
