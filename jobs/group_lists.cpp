#include "jobs/group_lists.h"

namespace rivulet {

std::uint32_t count_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                                  std::span<const std::int32_t> entry_group,
                                  std::span<std::uint32_t> counts) {
    for (auto& c : counts) c = 0;
    std::uint32_t isolated = 0;
    for (std::uint32_t e = bins.offsets[first_bin]; e < bins.offsets[end_bin]; ++e) {
        const std::int32_t g = entry_group[e];
        if (g < 0)
            ++isolated;
        else
            ++counts[static_cast<std::uint32_t>(g)];
    }
    return isolated;
}

void scatter_group_entries(BinTableView bins, std::uint32_t first_bin, std::uint32_t end_bin,
                           std::span<const std::int32_t> entry_group, std::span<std::uint32_t> cursors,
                           const GroupListsOut& out) {
    for (std::uint32_t b = first_bin; b < end_bin; ++b) {
        for (std::uint32_t e = bins.offsets[b]; e < bins.offsets[b + 1]; ++e) {
            const std::int32_t g = entry_group[e];
            if (g < 0) continue;
            const std::uint32_t slot = cursors[static_cast<std::uint32_t>(g)]++;
            const std::uint32_t particle = bins.entries[e];
            out.bin[slot] = b;
            out.particle[slot] = particle;
        }
    }
}

void mark_grouped_particles(std::span<const std::uint32_t> list_particle, std::span<std::uint8_t> grouped) {
    for (auto& f : grouped) f = 0;
    for (const std::uint32_t i : list_particle) grouped[i] = 1;
}

}  // namespace rivulet
