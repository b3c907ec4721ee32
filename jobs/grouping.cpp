#include "jobs/grouping.h"

#include <bit>
#include <cmath>
#include <limits>

namespace rivulet {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
// Below this many entries a linear scan of the bin beats building its hash.
constexpr std::uint32_t kLinearScanMax = 48;

struct CellCoord {
    std::int64_t x, z;
};

// A 2D hash of one bin's entries, cell size eps, bucket items sorted by position in the bin.
class BinHash {
  public:
    BinHash(std::span<std::uint32_t> start, std::span<std::uint32_t> items) : start_(start), items_(items) {}

    void build(ConstPositions p, std::span<const std::uint32_t> bin, float inv_cell) {
        inv_cell_ = inv_cell;
        const std::size_t slots = grouping_hash_slots(static_cast<std::uint32_t>(bin.size()));
        mask_ = static_cast<std::uint32_t>(slots - 1);
        for (std::size_t s = 0; s <= slots; ++s) start_[s] = 0;
        for (std::uint32_t e : bin) ++start_[bucket(cell_of(p, e)) + 1];
        for (std::size_t s = 0; s < slots; ++s) start_[s + 1] += start_[s];
        // Stable scatter through a moving cursor per bucket: reuse start_[b] and restore it afterwards.
        for (std::uint32_t pos = 0; pos < bin.size(); ++pos)
            items_[start_[bucket(cell_of(p, bin[pos]))]++] = pos;
        for (std::size_t s = slots; s > 0; --s) start_[s] = start_[s - 1];
        start_[0] = 0;
    }

    // Lowest bin position within the 3x3 cells around `pj`'s cell accepted by `accept(pos)`.
    // Only positions below `limit` count (for the current bin: entries placed before pj).
    template <class Accept>
    std::uint32_t first_match(ConstPositions p, std::uint32_t pj, std::uint32_t limit,
                              Accept&& accept) const {
        const CellCoord c = cell_of(p, pj);
        std::uint32_t best = limit;
        // Own cell first: its entries are the likeliest matches, and a low `best` cuts the other scans short.
        static constexpr int kOrder[9][2] = {{0, 0},   {-1, 0}, {1, 0},  {0, -1}, {0, 1},
                                             {-1, -1}, {1, -1}, {-1, 1}, {1, 1}};
        for (const auto& d : kOrder) {
            const std::uint32_t b = bucket({c.x + d[0], c.z + d[1]});
            for (std::uint32_t k = start_[b]; k < start_[b + 1]; ++k) {
                const std::uint32_t pos = items_[k];
                if (pos >= best) break;  // items ascend: nothing better in this bucket
                if (accept(pos)) {
                    best = pos;
                    break;
                }
            }
        }
        return best == limit ? kNone : best;
    }

  private:
    CellCoord cell_of(ConstPositions p, std::uint32_t i) const {
        return {static_cast<std::int64_t>(std::floor(p.x[i] * inv_cell_)),
                static_cast<std::int64_t>(std::floor(p.z[i] * inv_cell_))};
    }
    std::uint32_t bucket(CellCoord c) const {
        const auto h =
            static_cast<std::uint64_t>(c.x) * 0x9E3779B1ull ^ static_cast<std::uint64_t>(c.z) * 0x85EBCA77ull;
        return static_cast<std::uint32_t>(h ^ (h >> 29)) & mask_;
    }

    std::span<std::uint32_t> start_, items_;
    float inv_cell_ = 1;
    std::uint32_t mask_ = 0;
};

class Grouper {
  public:
    Grouper(ConstPositions p, BinTableView bins, const GroupingParams& params,
            std::span<std::int32_t> entry_group, const GroupingScratch& s)
        : p_(p),
          bins_(bins),
          params_(params),
          group_(entry_group),
          blocked_bin_(s.blocked_bin),
          eps2_(params.epsilon * params.epsilon),
          hashes_{BinHash(s.hash_start[0], s.hash_items[0]), BinHash(s.hash_start[1], s.hash_items[1])} {}

    GroupingResult run() {
        const std::uint32_t nbins = static_cast<std::uint32_t>(bins_.offsets.size()) - 1;
        for (std::uint32_t i = 0; i < params_.max_groups; ++i) blocked_bin_[i] = kNone;
        for (std::uint32_t b = 0; b < nbins; ++b) group_bin(b);
        for (std::int32_t g : group_) result_.isolated_entries += g < 0 ? 1u : 0u;
        return result_;
    }

  private:
    bool near(std::uint32_t a, std::uint32_t b) const {
        const float dx = p_.x[a] - p_.x[b], dy = p_.y[a] - p_.y[b], dz = p_.z[a] - p_.z[b];
        return dx * dx + dy * dy + dz * dz < eps2_;
    }

    // Position in `bin` of the first entry accepted, scanning linearly or through the bin's hash.
    template <class Accept>
    std::uint32_t first_in(std::span<const std::uint32_t> bin, std::uint32_t limit, const BinHash* hash,
                           std::uint32_t pj, Accept&& accept) const {
        if (!hash) {
            for (std::uint32_t pos = 0; pos < limit; ++pos)
                if (accept(pos)) return pos;
            return kNone;
        }
        (void)bin;
        return hash->first_match(p_, pj, limit, accept);
    }

    std::int32_t new_group(std::uint32_t pk_entry, std::uint32_t bin) {
        if (result_.groups >= params_.max_groups) {
            ++result_.pool_exhausted;
            return kIsolated;
        }
        const auto g = static_cast<std::int32_t>(result_.groups++);
        group_[pk_entry] = g;
        blocked_bin_[g] = bin;
        return g;
    }

    void group_bin(std::uint32_t b) {
        const std::uint32_t cur_base = bins_.offsets[b];
        const auto cur = bins_.bin(b);
        const std::uint32_t prev_base = b > 0 ? bins_.offsets[b - 1] : 0;
        const auto prev = b > 0 ? bins_.bin(b - 1) : std::span<const std::uint32_t>{};
        const BinHash* cur_hash = nullptr;
        if (cur.size() > kLinearScanMax) {
            BinHash& h = hashes_[b & 1];
            h.build(p_, cur, 1.0f / params_.epsilon);
            cur_hash = &h;
        }
        // The previous bin's hash was built last iteration into the other table.
        const BinHash* prev_hash = prev.size() > kLinearScanMax ? &hashes_[(b + 1) & 1] : nullptr;

        for (std::uint32_t j = 0; j < cur.size(); ++j) {
            const std::uint32_t pj = cur[j];
            std::int32_t& gj = group_[cur_base + j];
            const std::uint32_t c =
                first_in(cur, j, cur_hash, pj, [&](std::uint32_t pos) { return near(pj, cur[pos]); });
            if (c != kNone) {
                const std::int32_t gk = group_[cur_base + c];
                gj = gk >= 0 ? gk : new_group(cur_base + c, b);
            } else {
                const auto np = static_cast<std::uint32_t>(prev.size());
                const std::uint32_t q =
                    first_in(prev, np, prev_hash, pj, [&](std::uint32_t pos) { return near(pj, prev[pos]); });
                if (q == kNone) {
                    gj = kIsolated;
                } else if (const std::int32_t gk = group_[prev_base + q]; gk < 0) {
                    gj = new_group(prev_base + q, b);
                } else if (blocked_bin_[gk] == b) {
                    gj = kIsolated;
                } else {
                    gj = gk;
                    blocked_bin_[gk] = b;
                }
            }
        }
    }

    ConstPositions p_;
    BinTableView bins_;
    GroupingParams params_;
    std::span<std::int32_t> group_;
    std::span<std::uint32_t> blocked_bin_;
    float eps2_;
    BinHash hashes_[2];
    GroupingResult result_;
};

}  // namespace

std::size_t grouping_hash_slots(std::uint32_t max_bin_size) {
    return std::bit_ceil(std::size_t(max_bin_size) * 2u + 1u);
}

GroupingResult group_entries(ConstPositions particles, BinTableView bins, const GroupingParams& params,
                             std::span<std::int32_t> entry_group, const GroupingScratch& scratch) {
    return Grouper(particles, bins, params, entry_group, scratch).run();
}

}  // namespace rivulet
