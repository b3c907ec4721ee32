#include "jobs/sph_grid.h"

namespace rivulet {

void sph_grid_count_chunk(const SphGrid& grid, std::span<const float> x, std::span<const float> y,
                          std::span<const float> z, std::span<std::uint32_t> keys,
                          std::span<std::uint32_t> counts) {
    for (auto& c : counts) c = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        const std::uint32_t k = grid.key(x[i], y[i], z[i]);
        keys[i] = k;
        ++counts[k];
    }
}

std::uint32_t sph_grid_prefix(std::uint32_t cells, std::uint32_t chunks,
                              std::span<const std::uint32_t> counts, std::span<std::uint32_t> cursors,
                              std::span<std::uint32_t> cell_start) {
    std::uint32_t running = 0;
    for (std::uint32_t c = 0; c < cells; ++c) {
        cell_start[c] = running;
        for (std::uint32_t k = 0; k < chunks; ++k) {
            const std::size_t slot = std::size_t(k) * cells + c;
            cursors[slot] = running;
            running += counts[slot];
        }
    }
    cell_start[cells] = running;
    return running;
}

void sph_grid_scatter_chunk(const SphParticlesIn& in, std::span<const std::uint32_t> keys,
                            std::span<std::uint32_t> cursors, const SphSortedOut& out) {
    for (std::size_t i = 0; i < in.size(); ++i) {
        const std::uint32_t k = keys[i];
        const std::uint32_t e = cursors[k]++;
        out.x[e] = in.x[i], out.y[e] = in.y[i], out.z[e] = in.z[i];
        out.vx[e] = in.vx[i], out.vy[e] = in.vy[i], out.vz[e] = in.vz[i];
        out.id[e] = in.id[i];
        out.key[e] = k;
    }
}

}  // namespace rivulet
