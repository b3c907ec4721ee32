#pragma once
// The geometric half of grouping (seed 000 §2.2), independent per bin and so run in parallel: for each
// bin entry, the first entry (lowest position in bin order) within eps among the earlier entries of its
// own bin, and the first within eps in the bin above. The seed's rules then only look these up
// (grouping.h), so the serial part of grouping is a single cheap pass.
//
// Small bins (up to `linear_scan_max` entries) are scanned linearly, eight candidates at a time. Larger
// ones are bucketed by a 2D hash of cells 2 eps wide, so an eps-disc touches at most 2x2 cells; each
// bucket keeps its entries' positions contiguous and in bin order, so a query scans at most four short
// runs, eight candidates at a time, and stops at a bucket's first hit; a large bin's first 16 entries are
// tried in order before its buckets, which settles most queries in coherent streams. Same answer always.
#include <cstdint>
#include <limits>
#include <span>

#include "jobs/bin_sort.h"

namespace rivulet {

inline constexpr std::uint32_t kNoNeighbour = std::numeric_limits<std::uint32_t>::max();
inline constexpr std::uint32_t kDefaultLinearScanMax = 32;

// Per-bin hash tables of the whole bin table, laid out by bin offsets; sized with the functions below.
struct BinHashes {
    std::span<std::uint32_t> start;  // bin_hash_start_capacity(entries, bins)
    std::span<std::uint32_t> items;  // one per entry: position in the bin, bucket by bucket
    std::span<float> x, y, z;        // one per entry: the same entries' positions, same order
};

std::size_t bin_hash_start_capacity(std::size_t entries, std::size_t bins);

// Job 1, per bin: builds bin b's hash (nothing for small bins).
void build_bin_hash(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes,
                    std::uint32_t linear_scan_max = kDefaultLinearScanMax);

// Job 2, per bin (after job 1 for bins b and b-1): first_current[e] for every entry e of bin b, and
// first_above[e] where first_current[e] is kNoNeighbour, as global entry indices (else kNoNeighbour).
void find_bin_neighbours(BinTableView bins, std::uint32_t b, float eps, const BinHashes& hashes,
                         std::span<std::uint32_t> first_current, std::span<std::uint32_t> first_above,
                         std::uint32_t linear_scan_max = kDefaultLinearScanMax);

}  // namespace rivulet
