#include "jobs/group_lists.h"

namespace rivulet {

void build_group_lists(BinTableView bins, std::span<const std::int32_t> entry_group, std::uint32_t groups,
                       const GroupListsOut& out) {
    for (std::uint32_t g = 0; g <= groups; ++g) out.offsets[g] = 0;
    for (auto& f : out.grouped) f = 0;
    for (std::int32_t g : entry_group)
        if (g >= 0) ++out.offsets[g + 1];
    for (std::uint32_t g = 0; g < groups; ++g) {
        out.offsets[g + 1] += out.offsets[g];
        out.cursor[g] = out.offsets[g];
    }
    const std::uint32_t nbins = static_cast<std::uint32_t>(bins.offsets.size()) - 1;
    for (std::uint32_t b = 0; b < nbins; ++b) {
        for (std::uint32_t e = bins.offsets[b]; e < bins.offsets[b + 1]; ++e) {
            const std::int32_t g = entry_group[e];
            if (g < 0) continue;
            const std::uint32_t slot = out.cursor[g]++;
            out.bin[slot] = b;
            out.particle[slot] = bins.entries[e];
            out.grouped[bins.entries[e]] = 1;
        }
    }
    for (std::uint32_t g = 0; g < groups; ++g) {
        // Every group has at least two members, so its list is never empty.
        out.vmin[g] = out.bin[out.offsets[g]];
        out.vmax[g] = out.bin[out.offsets[g + 1] - 1];
    }
}

}  // namespace rivulet
