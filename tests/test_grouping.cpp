// Grouping (seed 000 §2.2): the seed's Figure 4, undercut blocking on an arch, and the hashed search
// against a plain linear-scan transcription of the pseudocode.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>
#include <set>

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
                                             std::uint32_t max_groups) {
    std::vector<std::int32_t> g(bins.entries.size(), -1);
    std::vector<std::int64_t> blocked(max_groups, -1);
    std::int32_t groups = 0;
    auto near = [&](std::uint32_t a, std::uint32_t b) {
        const float dx = c.x[a] - c.x[b], dy = c.y[a] - c.y[b], dz = c.z[a] - c.z[b];
        return dx * dx + dy * dy + dz * dz < eps * eps;
    };
    auto make = [&](std::size_t pk_entry, std::int64_t bin) -> std::int32_t {
        if (groups >= static_cast<std::int32_t>(max_groups)) return -1;
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
        const auto want = reference_grouping(c, bins, 0.1f, max_groups);
        // Every bin through the hash, every bin through the blocked linear scan, and the default mix.
        for (std::uint32_t linear_scan_max : {0u, 1u << 30, kDefaultLinearScanMax}) {
            const auto got = rivulet::test::group(c, bins, 0.1f, max_groups, nullptr, linear_scan_max);
            ASSERT_EQ(got, want) << "trial " << trial << ", linear scan up to " << linear_scan_max;
        }
    }
}

TEST(Grouping, GroupListsHoldEachGroupsEntriesInRingOrder) {
    const Cloud c = figure4(true);
    const Bins bins = rivulet::test::bin_sort(kFigureGrid, c);
    GroupingResult r;
    const auto eg = rivulet::test::group(c, bins, kFigureEps, 150, &r);
    const auto g = rivulet::test::particle_groups(bins, eg, c.size());
    std::vector<std::uint32_t> off(r.groups + 1), bin(bins.entries.size()), part(bins.entries.size()),
        vmin(r.groups), vmax(r.groups), cur(r.groups);
    std::vector<std::uint8_t> grouped(c.size());
    build_group_lists(bins.view(), eg, r.groups, {off, bin, part, vmin, vmax, cur, grouped});
    for (std::uint8_t f : grouped) EXPECT_EQ(f, 1);
    EXPECT_EQ(off.back(), 6u);
    for (std::uint32_t grp = 0; grp < r.groups; ++grp) {
        for (std::uint32_t e = off[grp]; e < off[grp + 1]; ++e) {
            EXPECT_EQ(g[part[e]], static_cast<std::int32_t>(grp));
            if (e > off[grp]) {
                EXPECT_LE(bin[e - 1], bin[e]);
            }
        }
    }
    EXPECT_EQ(vmin[static_cast<std::size_t>(g[A])], 0u);
    EXPECT_EQ(vmax[static_cast<std::size_t>(g[A])], 1u);
    EXPECT_EQ(vmin[static_cast<std::size_t>(g[E])], 1u);
}
