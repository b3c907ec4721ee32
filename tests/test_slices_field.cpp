// The marching-slices spacing field (systems/slices/slices_settings.h): the surface lies one radius
// outside the particles whatever their spacing; a lone particle is a sphere of one radius; the data's
// spacing is measured (jobs/particle_spacing.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "jobs/particle_spacing.h"
#include "support/test_support.h"
#include "systems/slices/slices_extractor.h"
#include "systems/slices/slices_settings_json.h"

using namespace rivulet;

namespace {

using Cloud = test::PointCloud;

SurfaceMesh extract(const Cloud& c, const SlicesSettings& s, SliceFieldValues* field = nullptr) {
    SlicesExtractor ex(s, c.size());
    SurfaceMesh mesh;
    ex.extract_serial(c.pos(), mesh);
    if (field) *field = ex.field();
    return mesh;
}

SlicesSettings spacing_settings(float radius) {
    SlicesSettings s;
    s.radius = radius;
    s.block_cubes = 16;
    return s;
}

float measured_spacing(const Cloud& c, float cell) {
    std::vector<std::uint32_t> heads(cell_hash_table_size(c.size()) + 1), order(c.size());
    std::vector<float> values(1024);
    const float origin[3] = {-100, -100, -100};
    return particle_spacing(c.pos(), origin, cell, 1024, {heads, order, values});
}

// A slab 12 radii square, at least 3 radii thick, of a cubic lattice `spacing` apart, its top layer at
// z = 0; each particle moved by up to `jitter` spacings on every axis.
Cloud flat_layer(float radius, float spacing, float jitter, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> move(-jitter * spacing, jitter * spacing);
    const int across = static_cast<int>(std::lround(12 * radius / spacing)) + 1;
    const int layers = static_cast<int>(std::ceil(3 * radius / spacing)) + 1;
    Cloud c;
    for (int k = 0; k < layers; ++k)
        for (int j = 0; j < across; ++j)
            for (int i = 0; i < across; ++i)
                c.add(spacing * float(i) + move(rng), spacing * float(j) + move(rng),
                      -spacing * float(k) + move(rng));
    return c;
}

std::size_t open_edges(const SurfaceMesh& m) {
    return test::count_open_edges(test::strided_positions({m.vertices6.data(), 6 * m.vertex_count}, 6),
                                  {m.indices.data(), m.index_count});
}

struct Offsets {
    double mean = 0, lo = 1e30, hi = -1e30;
    std::size_t count = 0;
};

// Heights of the top face's vertices (normal up, 3 radii or more inside the slab's edges), in radii.
Offsets top_offsets(const SurfaceMesh& m, float radius, float across) {
    Offsets o;
    for (std::size_t v = 0; v < m.vertex_count; ++v) {
        const float* p = m.vertices6.data() + 6 * v;
        if (p[5] < 0.5f || p[2] < 0) continue;
        if (p[0] < 3 * radius || p[0] > across - 3 * radius || p[1] < 3 * radius ||
            p[1] > across - 3 * radius)
            continue;
        const double h = p[2] / radius;
        o.mean += h, o.lo = std::min(o.lo, h), o.hi = std::max(o.hi, h), ++o.count;
    }
    o.mean /= double(std::max<std::size_t>(o.count, 1));
    return o;
}

}  // namespace

TEST(SpacingField, BisectionBracketsItsRootAndRcGrowsWithSpacing) {
    double last_rc = 1.0;
    for (double d = kMinFieldSpacing; d <= kMaxFieldSpacing + 1e-9; d += 0.05) {
        EXPECT_LT(lattice_mean_field(1.0001, d), lone_particle_iso(1.0001)) << d;
        const double hi = spacing_field_rc_bound(d);
        EXPECT_GT(lattice_mean_field(hi, d), lone_particle_iso(hi)) << d;
        const SpacingField f = spacing_field(d);
        EXPECT_GT(f.rc_factor, last_rc) << d;
        EXPECT_NEAR(lattice_mean_field(f.rc_factor, d), f.iso, 1e-9) << d;
        // A lone particle's sphere: R_c sqrt(1 - 2 sqrt(iso)) = 1.
        EXPECT_NEAR(f.rc_factor * std::sqrt(1.0 - 2.0 * std::sqrt(f.iso)), 1.0, 1e-9) << d;
        last_rc = f.rc_factor;
    }
    EXPECT_NEAR(spacing_field(2.0).rc_factor, 2.1955, 1e-3);  // a Python bisection over the same sum
    EXPECT_NEAR(spacing_field(0.5).rc_factor, 1.1130, 1e-3);
    EXPECT_EQ(spacing_field(0.01).spacing, kMinFieldSpacing);
    EXPECT_EQ(spacing_field(9.0).spacing, kMaxFieldSpacing);
    EXPECT_EQ(spacing_field(std::nan("")).spacing, kMaxFieldSpacing);
    EXPECT_NEAR(calibrated_iso(2.0), 0.1105, 1e-4) << "the classic field is unchanged";
}

TEST(ParticleSpacing, TheLatticeEdgeOfTheSameNumberDensity) {
    Cloud lattice, shaken;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> move(-0.4f * 0.3f, 0.4f * 0.3f);
    for (int k = 0; k < 12; ++k)
        for (int j = 0; j < 12; ++j)
            for (int i = 0; i < 12; ++i) {
                lattice.add(0.3f * float(i), 0.3f * float(j), 0.3f * float(k));
                shaken.add(0.3f * float(i) + move(rng), 0.3f * float(j) + move(rng),
                           0.3f * float(k) + move(rng));
            }
    EXPECT_NEAR(measured_spacing(lattice, 1.0f), 0.3f, 0.003f);
    EXPECT_EQ(measured_spacing(lattice, 0.2f), 0.2f) << "capped";
    // Particles moved by up to 0.4 spacings: their nearest neighbours sit far closer than 0.3, their
    // number density is the lattice's; its local fluctuations read a few percent dense.
    EXPECT_NEAR(measured_spacing(shaken, 1.0f), 0.3f, 0.015f);
    Cloud one;
    one.add(1, 2, 3);
    EXPECT_EQ(measured_spacing(one, 0.5f), 0.5f);
    Cloud pile;  // 20000 coincident particles: bounded work, spacing 0
    for (int i = 0; i < 20000; ++i) pile.add(0.5f, 0.5f, 0.5f);
    EXPECT_EQ(measured_spacing(pile, 0.5f), 0.0f);
    // A slab three layers thick (two thirds of it on the surface) still reads its lattice spacing.
    Cloud slab;
    for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 20; ++j)
            for (int i = 0; i < 20; ++i) slab.add(0.3f * float(i), 0.3f * float(j), 0.3f * float(k));
    EXPECT_NEAR(measured_spacing(slab, 1.0f), 0.3f, 0.01f);
}

TEST(SpacingField, FlatLayersAtAnySpacingHaveTheirSurfaceOneRadiusOut) {
    const float radius = 0.1f;
    for (const float ratio : {0.5f, 0.75f, 1.0f, 1.5f, 2.0f})
        for (const float jitter : {0.0f, 0.1f}) {
            const float spacing = ratio * radius;
            const Cloud c = flat_layer(radius, spacing, jitter, 5);
            SliceFieldValues field;
            const SurfaceMesh m = extract(c, spacing_settings(radius), &field);
            const float across = spacing * std::round(12 * radius / spacing);
            const Offsets o = top_offsets(m, radius, across);
            ASSERT_GT(o.count, 50u) << ratio;
            EXPECT_NEAR(o.mean, 1.0, 0.15) << "spacing " << ratio << " r, jitter " << jitter;
            if (jitter == 0) {
                // Thin slabs (three layers at 1.5 r) are mostly surface: a few percent over.
                EXPECT_NEAR(field.spacing, spacing, 0.04f * spacing) << "measured spacing";
                EXPECT_GT(o.lo, 0.9) << ratio;
                EXPECT_LT(o.hi, 1.1) << ratio;
            } else {
                // Jittered particles two radii apart leave dips between them (the classic field's deeper).
                EXPECT_GT(o.lo, 0.6) << ratio;
                EXPECT_LT(o.hi, 1.35) << ratio;
            }
            EXPECT_EQ(open_edges(m), 0u);
        }
}

TEST(SpacingField, ALoneParticleIsASphereOfOneRadius) {
    Cloud c;
    c.add(0.31f, -0.12f, 0.57f);
    const float radius = 0.1f;
    SliceFieldValues field;
    const SurfaceMesh m = extract(c, spacing_settings(radius), &field);
    EXPECT_FLOAT_EQ(field.spacing, float(kMaxFieldSpacing) * radius) << "no neighbour: the widest spacing";
    ASSERT_GT(m.vertex_count, 50u);
    for (std::size_t v = 0; v < m.vertex_count; ++v) {
        const float* p = m.vertices6.data() + 6 * v;
        const double d[3] = {p[0] - 0.31, p[1] + 0.12, p[2] - 0.57};
        // Within a tenth of a voxel (r / 2): linear interpolation along edges of a curved field.
        EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), radius, 0.05 * radius);
    }
    EXPECT_EQ(open_edges(m), 0u);
}

TEST(SpacingField, ABallOfDenseParticlesIsOneRadiusLarger) {
    // Particles of a cubic lattice within 5 radii of the centre, at spacings r / 2 and r: the mesh's
    // vertices lie, on average, one radius from their nearest particle centre (on the union of the
    // particles' spheres).
    const float radius = 0.05f, ball = 5 * radius;
    for (const float ratio : {0.5f, 1.0f}) {
        const float spacing = ratio * radius;
        const int n = static_cast<int>(ball / spacing);
        Cloud c;
        for (int k = -n; k <= n; ++k)
            for (int j = -n; j <= n; ++j)
                for (int i = -n; i <= n; ++i) {
                    const float x = spacing * float(i), y = spacing * float(j), z = spacing * float(k);
                    if (x * x + y * y + z * z <= ball * ball * 1.0001f) c.add(x, y, z);
                }
        const SurfaceMesh m = extract(c, spacing_settings(radius));
        double mean = 0;
        for (std::size_t v = 0; v < m.vertex_count; ++v) {
            const float* p = m.vertices6.data() + 6 * v;
            float nearest = 1e30f;
            for (std::size_t i = 0; i < c.size(); ++i) {
                const float dx = p[0] - c.x[i], dy = p[1] - c.y[i], dz = p[2] - c.z[i];
                nearest = std::min(nearest, dx * dx + dy * dy + dz * dz);
            }
            mean += std::sqrt(double(nearest));
        }
        mean /= double(m.vertex_count);
        EXPECT_NEAR(mean / radius, 1.0, 0.15) << "spacing " << ratio << " r";
        EXPECT_EQ(open_edges(m), 0u) << ratio;
    }
}

TEST(SpacingField, FixedByTheFirstFrameThatFillsTheSampleMeasuredPerFrameBefore) {
    const float radius = 0.1f;
    auto lattice = [](float spacing) {
        Cloud c;
        for (int k = 0; k < 12; ++k)
            for (int j = 0; j < 12; ++j)
                for (int i = 0; i < 12; ++i)
                    c.add(spacing * float(i), spacing * float(j), spacing * float(k));
        return c;
    };
    Cloud pair;
    pair.add(0, 0, 0);
    pair.add(0.1f, 0, 0);
    const Cloud wide = lattice(0.2f), close = lattice(0.1f);
    ASSERT_GE(wide.size(), SlicesExtractor::kSpacingSamples);
    SlicesExtractor ex(spacing_settings(radius), wide.size());
    SurfaceMesh m;
    ex.extract_serial(pair.pos(), m);
    // Two particles have the number density of a much wider lattice.
    EXPECT_GT(ex.field().spacing, 0.15f) << "measured for the pair";
    ex.extract_serial(close.pos(), m);
    EXPECT_NEAR(ex.field().spacing, 0.1f, 2e-3f) << "measured again";
    ex.extract_serial(wide.pos(), m);
    EXPECT_NEAR(ex.field().spacing, 0.1f, 2e-3f) << "kept from the first frame of 1,024 particles or more";
    SlicesExtractor fresh(spacing_settings(radius), wide.size());
    fresh.extract_serial(wide.pos(), m);
    EXPECT_NEAR(fresh.field().spacing, 0.2f, 4e-3f);
}

TEST(SpacingField, SettingsJsonRoundTripsTheFieldAndReadsOldFilesAsClassic) {
    SlicesSettings s;
    s.radius = 0.02f, s.spacing = 0.03f;
    const SlicesSettings back = slices_settings_from_json(slices_settings_to_json(s), "test");
    EXPECT_EQ(back.field, SliceField::kSpacing);
    EXPECT_EQ(back.spacing, 0.03f);
    nlohmann::json old = slices_settings_to_json(s);
    old.erase("field");
    EXPECT_EQ(slices_settings_from_json(old, "test").field, SliceField::kClassic) << "written before --field";
    for (const nlohmann::json& bad : {nlohmann::json("fuzzy"), nlohmann::json(3)}) {
        nlohmann::json doc = slices_settings_to_json(s);
        doc["field"] = bad;
        EXPECT_THROW(slices_settings_from_json(doc, "test"), std::invalid_argument) << bad;
    }
    nlohmann::json negative = slices_settings_to_json(s);
    negative["spacing"] = -1;
    EXPECT_THROW(slices_settings_from_json(negative, "test"), std::invalid_argument);
}
