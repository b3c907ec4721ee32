#include "jobs/bin_sort.h"

#include <cmath>

#include "jobs/cpu_dispatch.h"

namespace rivulet {

namespace {

struct PlaneRange {
    std::uint32_t first, end;
};

// A bin index from a float that may be anything (NaN goes to 0), so the conversion is always defined.
RIVULET_INLINE std::uint32_t clamp_bin(float x, float max_bin) {
    return static_cast<std::uint32_t>(
        static_cast<std::int32_t>(x > 0.0f ? (x < max_bin ? x : max_bin) : 0.0f));
}

// Planes [first, end) hit by a sphere at height y; first = end = 0 when it hits none. Plane b is hit when
// |y - plane_y(b)| <= radius, i.e. b in [(top - y - r) / s, (top - y + r) / s]. No branch, so a loop of
// these vectorizes.
RIVULET_INLINE PlaneRange plane_range(const BinGrid& grid, float y, float inv_spacing) {
    const float lo = std::ceil((grid.top - y - grid.radius) * inv_spacing);
    const float hi = std::floor((grid.top - y + grid.radius) * inv_spacing);
    const float max_bin = static_cast<float>(grid.bins) - 1.0f;
    const bool hit = hi >= 0.0f && lo <= max_bin && !(hi < lo);
    const std::uint32_t first = clamp_bin(lo, max_bin), last = clamp_bin(hi, max_bin);
    return {hit ? first : 0u, hit ? last + 1u : 0u};
}

// One reciprocal per chunk, not two divisions per particle.
RIVULET_INLINE void plane_ranges_body(const BinGrid& grid, std::span<const float> y,
                                      const ParticleBins& spans) {
    const float inv_spacing = 1.0f / grid.spacing;
    for (std::size_t i = 0; i < y.size(); ++i) {
        const PlaneRange r = plane_range(grid, y[i], inv_spacing);
        spans.first[i] = r.first, spans.end[i] = r.end;
    }
}

// Floor and ceil are single instructions from SSE4.1 on; the baseline calls them.
RIVULET_AVX2 void plane_ranges_avx2(const BinGrid& grid, std::span<const float> y,
                                    const ParticleBins& spans) {
    plane_ranges_body(grid, y, spans);
}

}  // namespace

bool BinGrid::span_of(float y, std::uint32_t& first, std::uint32_t& last) const {
    const PlaneRange r = plane_range(*this, y, 1.0f / spacing);
    if (r.end == 0) return false;
    first = r.first, last = r.end - 1;
    return true;
}

std::uint32_t BinGrid::max_bins_per_particle() const {
    return static_cast<std::uint32_t>(std::floor(2.0f * radius / spacing)) + 2u;
}

void bin_count_chunk(const BinGrid& grid, std::span<const float> y, std::span<std::uint32_t> counts,
                     const ParticleBins& spans) {
    if (cpu_has_avx2())
        plane_ranges_avx2(grid, y, spans);
    else
        plane_ranges_body(grid, y, spans);
    for (auto& c : counts) c = 0;
    for (std::size_t i = 0; i < y.size(); ++i)
        for (std::uint32_t b = spans.first[i]; b < spans.end[i]; ++b) ++counts[b];
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
