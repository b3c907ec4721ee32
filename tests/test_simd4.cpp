// jobs/simd4.h: lane order of the loads and the bit order of the masks, against plain per-lane code.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "jobs/simd4.h"

namespace {

using namespace rivulet;

std::array<float, 4> lanes(simd::F4 a) {
    std::array<float, 4> out{};
    simd::store(out.data(), a);
    return out;
}

TEST(Simd4, LoadPairsTakesTwoFromEachPointerInOrder) {
    const float row0[] = {1.0f, 2.0f, 99.0f}, row1[] = {3.0f, 4.0f, 98.0f};
    EXPECT_EQ(lanes(simd::load_pairs(row0, row1)), (std::array<float, 4>{1.0f, 2.0f, 3.0f, 4.0f}));
    EXPECT_EQ(lanes(simd::load_pairs(row1 + 1, row0 + 1)), (std::array<float, 4>{4.0f, 98.0f, 2.0f, 99.0f}));
}

TEST(Simd4, MasksMatchPerLaneComparisons) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float values[] = {0.5f, 0.1105f, -1.0f, -0.0f, 0.0f, 0.11f, nan, 2.0f};
    const simd::F4 iso = simd::splat(0.1105f);
    for (int at = 0; at + 4 <= 8; ++at) {
        const simd::F4 v = simd::load(values + at);
        unsigned geq = 0, sign = 0;
        for (unsigned k = 0; k < 4; ++k) {
            geq |= static_cast<unsigned>(values[at + int(k)] >= 0.1105f) << k;
            sign |= static_cast<unsigned>(std::signbit(values[at + int(k)])) << k;
        }
        EXPECT_EQ(simd::geq_mask(v, iso), geq) << at;
        EXPECT_EQ(simd::sign_mask(v), sign) << at;
    }
    // Corners not computed yet are -1: any of them shows in the sign mask; computed values (>= +0) do not.
    EXPECT_EQ(simd::sign_mask(simd::load_pairs(values + 3, values + 4)), 0b0001u);
    EXPECT_EQ(simd::sign_mask(simd::load_pairs(values + 4, values + 0)), 0u);
}

}  // namespace
