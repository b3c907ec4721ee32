// Grouping (Hoetzlein & Höllerer 2009 §2.2): the paper's Figure 4, undercut blocking on an arch, and the
// hashed search against a plain linear-scan transcription of the pseudocode.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>

#include "jobs/chunk_prefix.h"
#include "jobs/group_lists.h"
#include "support/scan_fixtures.h"

using namespace rivulet;
using rivulet::test::Bins;
using rivulet::test::Cloud;

namespace {

// Two planes, y = 1 (bin v1 of the figure) and y = 0.8 (bin v2); spheres small enough to cut one plane.
const BinGrid kFigureGrid{1.0f, 0.2f, 2, 0.05f};
constexpr float kFigureEps = 0.5f;

Cloud figure4(bool with_f) {
    Cloud c;
    c.add(0.0f, 1.0f, 0), c.add(0.4f, 1.0f, 0), c.add(0.8f, 1.0f, 0);  // A B C: group 1 in bin v1
    c.add(-0.1f, 0.8f, 0);                                             // D: near A
    c.add(1.1f, 0.8f, 0);                                              // E: near C only
    if (with_f) c.add(1.4f, 0.8f, 0);                                  // F: near E only
    return c;
}

enum { A, B, C, D, E, F };

}  // namespace

TEST(Grouping, Figure4DBlocksGroupOneSoEIsIsolated) {
    const Cloud c = figure4(false);
    GroupingResult r;
    const Bins bins = rivulet::test::bin_sort(kFigureGrid, c);
    ASSERT_EQ(bins.entries.size(), c.size()) << "each particle cuts exactly one plane in this figure";
    const auto g =
        rivulet::test::particle_groups(bins, rivulet::test::group(c, bins, kFigureEps, 150, &r), c.size());
    EXPECT_GE(g[A], 0);
    EXPECT_EQ(g[A], g[B]);
    EXPECT_EQ(g[A], g[C]);
    EXPECT_EQ(g[D], g[A]) << "D joins group 1 through A in the bin above";
    EXPECT_EQ(g[E], kIsolated) << "group 1 is blocked by D, so E near C must stay isolated";
    EXPECT_EQ(r.groups, 1u);
    EXPECT_EQ(r.isolated_entries, 1u);
}

TEST(Grouping, Figure4FFormsANewGroupWithE) {
    const Cloud c = figure4(true);
    GroupingResult r;
    const Bins bins = rivulet::test::bin_sort(kFigureGrid, c);
    const auto g =
        rivulet::test::particle_groups(bins, rivulet::test::group(c, bins, kFigureEps, 150, &r), c.size());
    EXPECT_EQ(g[D], g[A]);
    EXPECT_GE(g[E], 0);
    EXPECT_EQ(g[E], g[F]);
    EXPECT_NE(g[E], g[A]);
    EXPECT_EQ(r.groups, 2u);
    EXPECT_EQ(r.isolated_entries, 0u);
}

TEST(Grouping, ArchIsSplitNeverWrappedDownBothLegs) {
    // An arch in the x-y plane: apex at y = 1, legs down to y = 0 at x = -0.5 and x = +0.5.
    Cloud c;
    const float radius = 0.02f;
    for (int i = 0; i <= 400; ++i) {
        const float t = std::numbers::pi_v<float> * static_cast<float>(i) / 400.0f;
        c.add(0.5f * std::cos(t), 0.5f + 0.5f * std::sin(t), 0.0f);
        if (i == 0 || i == 400)  // legs continue straight down
            for (int k = 1; k <= 25; ++k) c.add(c.x.back(), 0.5f - 0.02f * static_cast<float>(k), 0.0f);
    }
    const BinGrid grid{1.05f, 0.02f, 56, radius};
    const Bins bins = rivulet::test::bin_sort(grid, c);
    const auto g = rivulet::test::group(c, bins, 3.5f * radius, 150);
    std::map<std::int32_t, std::set<int>>
        legs;  // group -> which legs (-1 / +1) it reaches below the apex region
    for (std::size_t e = 0; e < bins.entries.size(); ++e) {
        const std::uint32_t i = bins.entries[e];
        if (g[e] >= 0 && c.y[i] < 0.8f) legs[g[e]].insert(c.x[i] < 0 ? -1 : 1);
    }
    ASSERT_FALSE(legs.empty());
    for (const auto& [group, sides] : legs)
        EXPECT_EQ(sides.size(), 1u) << "group " << group << " wraps both legs";
    // Both legs are still surfaced by some group (not left as isolated spheres).
    std::set<int> covered;
    for (const auto& [group, sides] : legs) covered.insert(sides.begin(), sides.end());
    EXPECT_EQ(covered.size(), 2u);
}

namespace {

// The pseudocode over bin entries with this implementation's stated decisions, scanning linearly.
std::vector<std::int32_t> reference_grouping(const Cloud& c, const Bins& bins, float eps,
                                             std::uint32_t max_groups, std::uint32_t& pool_exhausted) {
    pool_exhausted = 0;
    std::vector<std::int32_t> g(bins.entries.size(), -1);
    std::vector<std::int64_t> blocked(max_groups, -1);
    std::int32_t groups = 0;
    auto near = [&](std::uint32_t a, std::uint32_t b) {
        const float dx = c.x[a] - c.x[b], dy = c.y[a] - c.y[b], dz = c.z[a] - c.z[b];
        return dx * dx + dy * dy + dz * dz < eps * eps;
    };
    auto make = [&](std::size_t pk_entry, std::int64_t bin) -> std::int32_t {
        if (groups >= static_cast<std::int32_t>(max_groups)) {
            ++pool_exhausted;
            return -1;
        }
        g[pk_entry] = groups;
        blocked[groups] = bin;
        return groups++;
    };
    const auto nb = static_cast<std::int64_t>(bins.offsets.size()) - 1;
    for (std::int64_t b = 0; b < nb; ++b) {
        const std::size_t cb = bins.offsets[b], ce = bins.offsets[b + 1];
        const std::size_t pb = b > 0 ? bins.offsets[b - 1] : 0, pe = b > 0 ? cb : 0;
        for (std::size_t j = cb; j < ce; ++j) {
            const std::uint32_t pj = bins.entries[j];
            bool done = false;
            for (std::size_t k = cb; k < j && !done; ++k) {
                if (!near(pj, bins.entries[k])) continue;
                g[j] = g[k] >= 0 ? g[k] : make(k, b);
                done = true;
            }
            for (std::size_t k = pb; k < pe && !done; ++k) {
                if (!near(pj, bins.entries[k])) continue;
                if (g[k] < 0) {
                    g[j] = make(k, b);
                } else if (blocked[g[k]] == b) {
                    g[j] = -1;
                } else {
                    g[j] = g[k], blocked[g[k]] = b;
                }
                done = true;
            }
        }
    }
    return g;
}

}  // namespace

TEST(Grouping, HashedAndBlockedSearchesMatchTheLinearPseudocode) {
    std::mt19937 rng(11);
    for (int trial = 0; trial < 6; ++trial) {
        Cloud c;
        std::normal_distribution<float> jitter(0.0f, 0.04f + 0.02f * static_cast<float>(trial));
        std::uniform_real_distribution<float> unit(0.0f, 1.0f);
        // Several falling streams with splashes: bins of hundreds of entries exercise the hash path.
        for (int s = 0; s < 5; ++s) {
            const float cx = unit(rng) * 2 - 1, cz = unit(rng) * 2 - 1;
            for (int i = 0; i < 900; ++i) c.add(cx + jitter(rng), unit(rng) * 2.0f, cz + jitter(rng));
        }
        for (int i = 0; i < 300; ++i) c.add(unit(rng) * 4 - 2, unit(rng) * 2, unit(rng) * 4 - 2);
        const BinGrid grid{2.0f, 0.1f, 21, 0.03f};
        const Bins bins = rivulet::test::bin_sort(grid, c);
        const std::uint32_t max_groups = trial % 2 ? 150 : 12;  // also when the pool runs out
        std::uint32_t want_exhausted = 0;
        const auto want = reference_grouping(c, bins, 0.1f, max_groups, want_exhausted);
        if (max_groups == 12) {
            EXPECT_GT(want_exhausted, 0u) << "trial " << trial << " should run the pool out";
        }
        // Every bin through the hash, every bin through the blocked linear scan, and the default mix.
        for (std::uint32_t linear_scan_max : {0u, 1u << 30, kDefaultLinearScanMax}) {
            GroupingResult r;
            const auto got = rivulet::test::group(c, bins, 0.1f, max_groups, &r, linear_scan_max);
            ASSERT_EQ(got, want) << "trial " << trial << ", linear scan up to " << linear_scan_max;
            EXPECT_EQ(r.pool_exhausted, want_exhausted) << "trial " << trial;
        }
    }
}

namespace {

struct Lists {
    std::vector<std::uint32_t> offsets, bin, particle;
    std::vector<std::uint8_t> grouped;
};

// The group lists built in chunks of `chunk_bins` bins, as the frame graph runs them.
Lists group_lists_in_chunks(const Bins& bins, const std::vector<std::int32_t>& eg, std::uint32_t groups,
                            std::size_t particles, std::uint32_t chunk_bins) {
    const auto nbins = static_cast<std::uint32_t>(bins.offsets.size() - 1);
    const std::uint32_t chunks = (nbins + chunk_bins - 1) / chunk_bins;
    std::vector<std::uint32_t> counts(std::size_t(chunks) * groups), cursors(counts.size());
    for (std::uint32_t c = 0; c < chunks; ++c)
        count_group_entries(bins.view(), c * chunk_bins, std::min(nbins, (c + 1) * chunk_bins), eg,
                            std::span(counts).subspan(std::size_t(c) * groups, groups));
    Lists l{std::vector<std::uint32_t>(groups + 1), std::vector<std::uint32_t>(eg.size()),
            std::vector<std::uint32_t>(eg.size()), std::vector<std::uint8_t>(particles)};
    chunk_major_prefix(groups, chunks, groups, counts, cursors, l.offsets);
    for (std::uint32_t c = chunks; c-- > 0;)  // any order: each chunk has its own cursors
        scatter_group_entries(bins.view(), c * chunk_bins, std::min(nbins, (c + 1) * chunk_bins), eg,
                              std::span(cursors).subspan(std::size_t(c) * groups, groups),
                              {l.bin, l.particle});
    mark_grouped_particles(std::span(l.particle).first(l.offsets.back()), l.grouped);
    return l;
}

}  // namespace

TEST(Grouping, GroupListsHoldEachGroupsEntriesInRingOrder) {
    const Cloud c = figure4(true);
    const Bins bins = rivulet::test::bin_sort(kFigureGrid, c);
    GroupingResult r;
    std::vector<std::uint32_t> vmin, vmax;
    const auto eg = rivulet::test::group(c, bins, kFigureEps, 150, &r, kDefaultLinearScanMax, &vmin, &vmax);
    const auto g = rivulet::test::particle_groups(bins, eg, c.size());
    const Lists l = group_lists_in_chunks(bins, eg, r.groups, c.size(), 1);
    for (std::uint8_t f : l.grouped) EXPECT_EQ(f, 1);
    EXPECT_EQ(l.offsets.back(), 6u);
    for (std::uint32_t grp = 0; grp < r.groups; ++grp) {
        for (std::uint32_t e = l.offsets[grp]; e < l.offsets[grp + 1]; ++e) {
            EXPECT_EQ(g[l.particle[e]], static_cast<std::int32_t>(grp));
            if (e > l.offsets[grp]) {
                EXPECT_LE(l.bin[e - 1], l.bin[e]);
            }
        }
    }
    EXPECT_EQ(vmin[static_cast<std::size_t>(g[A])], 0u);
    EXPECT_EQ(vmax[static_cast<std::size_t>(g[A])], 1u);
    EXPECT_EQ(vmin[static_cast<std::size_t>(g[E])], 1u);
}

TEST(Grouping, ChunkedListsAndRingRangesAgreeOnRandomStreams) {
    std::mt19937 rng(5);
    std::normal_distribution<float> jitter(0.0f, 0.05f);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    Cloud c;
    for (int s = 0; s < 6; ++s) {
        const float cx = unit(rng) * 2 - 1, cz = unit(rng) * 2 - 1;
        for (int i = 0; i < 400; ++i) c.add(cx + jitter(rng), unit(rng) * 2.0f, cz + jitter(rng));
    }
    const BinGrid grid{2.0f, 0.1f, 21, 0.03f};
    const Bins bins = rivulet::test::bin_sort(grid, c);
    GroupingResult r;
    std::vector<std::uint32_t> vmin, vmax;
    const auto eg = rivulet::test::group(c, bins, 0.1f, 150, &r, kDefaultLinearScanMax, &vmin, &vmax);
    ASSERT_GT(r.groups, 3u);
    const Lists whole = group_lists_in_chunks(bins, eg, r.groups, c.size(), 1000);
    for (std::uint32_t chunk_bins : {1u, 2u, 5u}) {
        const Lists split = group_lists_in_chunks(bins, eg, r.groups, c.size(), chunk_bins);
        EXPECT_EQ(split.offsets, whole.offsets) << chunk_bins;
        EXPECT_EQ(split.bin, whole.bin) << chunk_bins;
        EXPECT_EQ(split.particle, whole.particle) << chunk_bins;
        EXPECT_EQ(split.grouped, whole.grouped) << chunk_bins;
    }
    // The ring range the rules recorded is the first and last ring of the group's list, and every ring
    // in between holds at least one of its entries (a cylinder has no empty cross-section).
    for (std::uint32_t grp = 0; grp < r.groups; ++grp) {
        ASSERT_LT(whole.offsets[grp], whole.offsets[grp + 1]) << "group " << grp;
        EXPECT_EQ(vmin[grp], whole.bin[whole.offsets[grp]]) << "group " << grp;
        EXPECT_EQ(vmax[grp], whole.bin[whole.offsets[grp + 1] - 1]) << "group " << grp;
        for (std::uint32_t e = whole.offsets[grp] + 1; e < whole.offsets[grp + 1]; ++e)
            EXPECT_LE(whole.bin[e] - whole.bin[e - 1], 1u) << "group " << grp << " skips a ring";
    }
    // isolated_entries counts what the lists left out.
    EXPECT_EQ(r.isolated_entries, eg.size() - whole.offsets.back());
}
