#include "jobs/spray_split.h"

#include <algorithm>
#include <cmath>

namespace rivulet {

namespace {

std::int32_t cell_index(float v, float cell) {
    const float f = std::floor(v / cell);
    constexpr float kLimit = static_cast<float>(SprayGrid::kCellLimit);
    if (std::isnan(f)) return 0;
    return static_cast<std::int32_t>(std::clamp(f, -kLimit, kLimit));
}

std::int32_t unpack(std::uint64_t key, int shift) {
    return static_cast<std::int32_t>((key >> shift) & 0x1FFFFF) - (SprayGrid::kCellLimit + 1);
}

// Particles of the sorted cells within grid.cell of p (p's own entry included), counted up to `want`.
std::uint32_t found_near(const SprayGrid& grid, const SprayCells& cells, float px, float py, float pz,
                         std::uint64_t key, std::uint32_t want) {
    const float reach2 = grid.cell * grid.cell;
    const std::int32_t ix = unpack(key, 0), iy = unpack(key, 21), iz = unpack(key, 42);
    const auto inside = [](std::int32_t c) {
        return c >= -SprayGrid::kCellLimit && c <= SprayGrid::kCellLimit;
    };
    // Own cell first: in bulk fluid it alone usually reaches `want`.
    static constexpr std::int32_t kOrder[3] = {0, -1, 1};
    std::uint32_t found = 0;
    for (std::int32_t dz : kOrder) {
        for (std::int32_t dy : kOrder) {
            for (std::int32_t dx : kOrder) {
                if (!inside(ix + dx) || !inside(iy + dy) || !inside(iz + dz)) continue;
                const std::uint64_t k = SprayGrid::pack(ix + dx, iy + dy, iz + dz);
                const std::uint32_t b = grid.bucket(k);
                for (std::uint32_t e = cells.bucket_start[b], end = cells.bucket_start[b + 1]; e < end; ++e) {
                    if (cells.key[e] != k) continue;  // another cell sharing the bucket
                    const float ex = cells.x[e] - px, ey = cells.y[e] - py, ez = cells.z[e] - pz;
                    if (ex * ex + ey * ey + ez * ez <= reach2 && ++found == want) return found;
                }
            }
        }
    }
    return found;
}

}  // namespace

std::uint64_t SprayGrid::key(float x, float y, float z) const {
    return pack(cell_index(x, cell), cell_index(y, cell), cell_index(z, cell));
}

std::uint32_t SprayGrid::bits_for(std::size_t max_particles) {
    std::uint32_t bits = 6;
    while (bits < 24 && (std::size_t{1} << bits) * 4 < max_particles) ++bits;
    return bits;
}

void spray_grid_chunk(const SprayGrid& grid, ConstPositions chunk, std::span<std::uint64_t> keys,
                      std::span<std::uint32_t> counts) {
    std::fill(counts.begin(), counts.begin() + grid.buckets(), 0u);
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        keys[i] = grid.key(chunk.x[i], chunk.y[i], chunk.z[i]);
        ++counts[grid.bucket(keys[i])];
    }
}

void spray_scatter_chunk(const SprayGrid& grid, ConstPositions chunk, std::span<const std::uint64_t> keys,
                         std::span<std::uint32_t> cursors, const SprayCellsOut& out) {
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        const std::uint32_t at = cursors[grid.bucket(keys[i])]++;
        out.x[at] = chunk.x[i], out.y[at] = chunk.y[i], out.z[at] = chunk.z[i];
        out.key[at] = keys[i];
    }
}

std::uint32_t spray_count_chunk(const SprayGrid& grid, const SprayCells& cells, ConstPositions chunk,
                                std::span<const std::uint64_t> keys, std::uint32_t cap,
                                std::span<std::uint32_t> counts) {
    std::uint32_t capped = 0;
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        // The particle finds itself (at distance 0), so it looks for cap + 1; NaN finds nothing.
        const std::uint32_t found =
            found_near(grid, cells, chunk.x[i], chunk.y[i], chunk.z[i], keys[i], cap + 1);
        counts[i] = found > 0 ? found - 1 : 0;
        capped += counts[i] >= cap ? 1u : 0u;
    }
    return capped;
}

void spray_split_chunk(ConstPositions chunk, std::span<const std::uint32_t> counts, std::uint32_t threshold,
                       std::size_t fluid_at, std::size_t spray_at, const SprayPositionsOut& fluid,
                       const SprayPositionsOut& spray) {
    for (std::size_t i = 0; i < chunk.size(); ++i) {
        const bool is_fluid = counts[i] >= threshold;
        const SprayPositionsOut& out = is_fluid ? fluid : spray;
        std::size_t& at = is_fluid ? fluid_at : spray_at;
        out.x[at] = chunk.x[i], out.y[at] = chunk.y[i], out.z[at] = chunk.z[i];
        ++at;
    }
}

}  // namespace rivulet
