#pragma once
// Small builders shared by the scan-conversion tests: particles in SoA vectors and a bin table.
#include <cstdint>
#include <vector>

#include "jobs/bin_sort.h"
#include "jobs/grouping.h"
#include "jobs/particle_spans.h"

namespace rivulet::test {

struct Cloud {
    std::vector<float> x, y, z;
    void add(float px, float py, float pz) { x.push_back(px), y.push_back(py), z.push_back(pz); }
    ConstPositions view() const { return {x, y, z}; }
    std::size_t size() const { return x.size(); }
};

struct Bins {
    std::vector<std::uint32_t> offsets, entries;
    std::vector<float> ex, ey, ez;
    BinTableView view() const { return {offsets, entries, ex, ey, ez}; }
};

// Single-chunk bin sort.
Bins bin_sort(const BinGrid& grid, const Cloud& c);

// Runs group_entries with scratch sized for this input; returns the group of every bin entry, and when
// asked each group's ring range as assign_groups found it.
std::vector<std::int32_t> group(const Cloud& c, const Bins& bins, float eps, std::uint32_t max_groups,
                                GroupingResult* result = nullptr,
                                std::uint32_t linear_scan_max = kDefaultLinearScanMax,
                                std::vector<std::uint32_t>* vmin = nullptr,
                                std::vector<std::uint32_t>* vmax = nullptr);

// Per particle: the group of its first grouped entry, or kIsolated.
std::vector<std::int32_t> particle_groups(const Bins& bins, const std::vector<std::int32_t>& entry_group,
                                          std::size_t n);

}  // namespace rivulet::test
