#pragma once
// The geometric half of grouping (Hoetzlein & Höllerer 2009 §2.2), independent per bin and so run in
// parallel: for each bin entry, the first entry (lowest position in bin order) within eps among the earlier
// entries of its own bin, and the first within eps in the bin above. The paper's rules then only look these
// up (grouping.h), so the serial part of grouping is a single cheap pass.
//
// A query first scans the bin's leading `linear_scan_max` entries in order, four at a time; in a
// coherent stream that settles almost every query, and a bin no larger than that is only ever scanned.
// Past it, the bin gets a 2D hash of cells 2 eps wide (an eps-disc touches at most 2x2 cells) whose
// buckets keep their entries' positions contiguous and in bin order, so a query scans at most four short
// runs and stops at a bucket's first hit. Once a bin has its hash, its later queries probe only a few
// leading entries: a bin crossed by many streams (a fountain's arcs) fails long probes again and again.
// The hash is built lazily, by the one job that needs it: the
// job of bin b builds bin b's table in `own` and its own copy of bin b-1's table in `above`, so jobs
// share nothing they write and there is no separate hashing pass. The same answer every way.
#include <cstdint>
#include <limits>
#include <span>

#include "jobs/bin_sort.h"

namespace rivulet {

inline constexpr std::uint32_t kNoNeighbour = std::numeric_limits<std::uint32_t>::max();
// A link with this bit set names an entry of the bin above; entry indices stay below 2^31 - 1.
inline constexpr std::uint32_t kLinkAbove = 1u << 31;
inline constexpr std::uint32_t kDefaultLinearScanMax = 64;

// Per-bin hash tables of the whole bin table, laid out by bin offsets; sized with the function below.
struct BinHashes {
    std::span<std::uint32_t> start;   // bin_hash_start_capacity(entries, bins)
    std::span<std::uint32_t> items;   // one per entry: position in the bin, bucket by bucket
    std::span<float> x, y, z;         // one per entry: the same entries' positions, same order
    std::span<std::uint32_t> bucket;  // one per entry: scratch, each entry's bucket in bin order
};

std::size_t bin_hash_start_capacity(std::size_t entries, std::size_t bins);

// One job per bin: link[e] for every entry e of bin b, all the paper's rules need of its neighbours: the
// global index of the first earlier entry of bin b within eps; else, when there is none, the first entry
// of bin b-1 within eps, or-ed with kLinkAbove; else kNoNeighbour. One word per entry keeps what the
// serial rules pass reads small. `own` and `above` are two separate tables of the same size (see above);
// only bin b's region of `own` and bin b-1's region of `above` are written.
void find_bin_neighbours(BinTableView bins, std::uint32_t b, float eps, const BinHashes& own,
                         const BinHashes& above, std::span<std::uint32_t> link,
                         std::uint32_t linear_scan_max = kDefaultLinearScanMax);

}  // namespace rivulet
