// write_vdb: the file read back with OpenVDB's own reader, as Houdini or Blender would read it.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "support/test_support.h"
#include "systems/io/vdb_writer.h"

namespace rivulet {
namespace {

// A volume built by hand: the bricks `keep` selects, in reverse brick order so that slots and bricks are
// numbered differently, each sample `field` at its lattice point. A sample shared by two bricks is
// computed from the same lattice index, so both copies agree, as the volume promises. Atlas entries no
// brick owns are NaN: a read from the wrong place cannot pass for a value.
class HandVolume {
  public:
    using Field = std::function<float(float, float, float)>;
    using Keep = std::function<bool(std::uint32_t, std::uint32_t, std::uint32_t)>;

    HandVolume(const DensityGrid& grid, float iso, const Keep& keep, const Field& field)
        : grid_(grid), iso_(iso), field_(field) {
        brick_slot_.assign(grid.bricks(), -1);
        for (std::uint32_t brick = grid.bricks(); brick-- > 0;) {
            const std::uint32_t a = brick % grid.bx, b = (brick / grid.bx) % grid.by,
                                c = brick / (grid.bx * grid.by);
            if (!keep(a, b, c)) continue;
            brick_slot_[brick] = static_cast<std::int32_t>(slot_brick_.size());
            slot_brick_.push_back(brick);
        }
        const auto slots = static_cast<std::uint32_t>(slot_brick_.size());
        atlas_.assign(atlas_samples(atlas_layers(slots)), std::numeric_limits<float>::quiet_NaN());
        for (std::uint32_t s = 0; s < slots; ++s) {
            const std::uint32_t brick = slot_brick_[s];
            const std::uint32_t a = brick % grid.bx, b = (brick / grid.bx) % grid.by,
                                c = brick / (grid.bx * grid.by);
            float lo = std::numeric_limits<float>::infinity(), hi = -lo;
            for (std::uint32_t k = 0; k < kBrickEdge; ++k) {
                for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
                    for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                        const float f = value(a * kBrickCells + i, b * kBrickCells + j, c * kBrickCells + k);
                        atlas_[atlas_offset(s, i, j, k)] = f;
                        lo = std::min(lo, f);
                        hi = std::max(hi, f);
                    }
                }
            }
            slot_min_.push_back(lo);
            slot_max_.push_back(hi);
        }
    }

    DensityVolumeView view() const {
        return DensityVolumeView{grid_, iso_, brick_slot_, slot_brick_, slot_min_, slot_max_, atlas_};
    }
    float value(std::uint32_t i, std::uint32_t j, std::uint32_t k) const {
        return field_(grid_.x(i), grid_.y(j), grid_.z(k));
    }
    // Whether lattice point (i, j, k) belongs to a stored brick (a shared face counts for both bricks).
    bool covered(std::int64_t i, std::int64_t j, std::int64_t k) const {
        if (i < 0 || j < 0 || k < 0 || i >= grid_.samples_x() || j >= grid_.samples_y() ||
            k >= grid_.samples_z()) {
            return false;
        }
        const auto bricks_of = [](std::int64_t s, std::uint32_t n, std::uint32_t out[2]) {
            int count = 0;
            const auto hi = static_cast<std::uint32_t>(s / kBrickCells);
            if (hi < n) out[count++] = hi;
            if (s % kBrickCells == 0 && hi > 0) out[count++] = hi - 1;
            return count;
        };
        std::uint32_t as[2], bs[2], cs[2];
        const int na = bricks_of(i, grid_.bx, as), nb = bricks_of(j, grid_.by, bs),
                  nc = bricks_of(k, grid_.bz, cs);
        for (int x = 0; x < na; ++x) {
            for (int y = 0; y < nb; ++y) {
                for (int z = 0; z < nc; ++z) {
                    if (brick_slot_[grid_.brick_index(as[x], bs[y], cs[z])] >= 0) return true;
                }
            }
        }
        return false;
    }
    std::uint32_t stored() const { return static_cast<std::uint32_t>(slot_brick_.size()); }

  private:
    DensityGrid grid_;
    float iso_;
    Field field_;
    std::vector<std::int32_t> brick_slot_;
    std::vector<std::uint32_t> slot_brick_;
    std::vector<float> slot_min_, slot_max_, atlas_;
};

DensityGrid small_grid(float ox, float oy, float oz, float voxel) {
    DensityGrid g;
    g.ox = ox;
    g.oy = oy;
    g.oz = oz;
    g.voxel = voxel;
    g.bx = 3;
    g.by = 2;
    g.bz = 2;
    return g;
}

openvdb::GridPtrVecPtr read_grids(const std::string& path) {
    openvdb::initialize();
    openvdb::io::File file(path);
    file.open(/*delayLoad=*/false);
    openvdb::GridPtrVecPtr grids = file.getGrids();
    file.close();
    return grids;
}

openvdb::FloatGrid::Ptr float_grid(const openvdb::GridPtrVecPtr& grids, const std::string& name) {
    for (const auto& g : *grids) {
        if (g->getName() == name) return openvdb::gridPtrCast<openvdb::FloatGrid>(g);
    }
    return nullptr;
}

// index (i, j, k) -> (ox + voxel i, oy + voxel j, oz + voxel k), computed as OpenVDB does, in double.
void expect_lattice_transform(const openvdb::GridBase& grid, const DensityGrid& g) {
    EXPECT_EQ(grid.voxelSize(), openvdb::Vec3d(double(g.voxel)));
    for (const openvdb::Coord ijk :
         {openvdb::Coord(0, 0, 0), openvdb::Coord(1, 0, 0), openvdb::Coord(0, 7, 3),
          openvdb::Coord(24, 16, 16), openvdb::Coord(-3, 40, 9)}) {
        const openvdb::Vec3d w = grid.indexToWorld(ijk);
        EXPECT_NEAR(w.x(), double(g.ox) + double(g.voxel) * ijk.x(), 1e-12) << ijk;
        EXPECT_NEAR(w.y(), double(g.oy) + double(g.voxel) * ijk.y(), 1e-12) << ijk;
        EXPECT_NEAR(w.z(), double(g.oz) + double(g.voxel) * ijk.z(), 1e-12) << ijk;
    }
}

void expect_rivulet_metadata(const openvdb::GridBase& grid, float iso) {
    EXPECT_EQ(grid.metaValue<std::string>("creator"), "rivulet");
    EXPECT_EQ(grid.metaValue<float>("iso"), iso);
}

TEST(VdbWriter, DensityGridHoldsEveryStoredSampleExactly) {
    const DensityGrid g = small_grid(-0.35f, 0.2f, 1.5f, 0.05f);
    // A checkerboard of bricks: every stored brick has unstored neighbours, so far faces that only it
    // holds (non-zero here) must be written into the leaves of bricks that are not there.
    const HandVolume hand(
        g, 0.4f, [](std::uint32_t a, std::uint32_t b, std::uint32_t c) { return (a + b + c) % 2 == 0; },
        [](float x, float y, float z) {
            return 0.3f + 0.5f * std::sin(3.0f * x) * std::cos(2.0f * y) + 0.25f * z;
        });
    ASSERT_EQ(hand.stored(), 6u);
    const std::string path = test::temp_path("density.vdb");
    write_vdb(path, hand.view());

    const openvdb::GridPtrVecPtr grids = read_grids(path);
    ASSERT_EQ(grids->size(), 1u);  // no level set unless asked
    const openvdb::FloatGrid::Ptr grid = float_grid(grids, "density");
    ASSERT_TRUE(grid);
    EXPECT_EQ(grid->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(grid->background(), 0.0f);
    expect_lattice_transform(*grid, g);
    expect_rivulet_metadata(*grid, 0.4f);

    // Every lattice point and a margin around the lattice: stored samples active with their exact value,
    // everything else inactive background.
    const auto acc = grid->getConstAccessor();
    std::uint64_t covered = 0;
    for (std::int32_t k = -2; k < std::int32_t(g.samples_z()) + 2; ++k) {
        for (std::int32_t j = -2; j < std::int32_t(g.samples_y()) + 2; ++j) {
            for (std::int32_t i = -2; i < std::int32_t(g.samples_x()) + 2; ++i) {
                const openvdb::Coord ijk(i, j, k);
                if (hand.covered(i, j, k)) {
                    ++covered;
                    const float expected = hand.value(std::uint32_t(i), std::uint32_t(j), std::uint32_t(k));
                    ASSERT_TRUE(acc.isValueOn(ijk)) << ijk;
                    ASSERT_EQ(acc.getValue(ijk), expected) << ijk;
                } else {
                    ASSERT_FALSE(acc.isValueOn(ijk)) << ijk;
                    ASSERT_EQ(acc.getValue(ijk), 0.0f) << ijk;
                }
            }
        }
    }
    EXPECT_EQ(grid->activeVoxelCount(), covered);
}

TEST(VdbWriter, LevelSetIsTheSignedDistanceToTheIsoSurface) {
#if defined(__SANITIZE_THREAD__)
    // The level set is built inside libopenvdb, which is not instrumented: its worker threads hand nodes
    // to each other through oneTBB code inlined there, so ThreadSanitizer sees only the allocations.
    GTEST_SKIP() << "libopenvdb's own threads are invisible to ThreadSanitizer";
#endif
    const DensityGrid g = small_grid(-0.05f, 0.1f, 0.2f, 0.1f);
    const double cx = g.ox + 1.0, cy = g.oy + 0.8, cz = g.oz + 0.8, R = 0.55;
    const float iso = 0.5f;
    // A smooth ball F = max(0, 1 - |p - c|^2 / R^2): F = iso on the sphere of radius R sqrt(1 - iso).
    const auto ball = [&](float x, float y, float z) {
        const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz);
        return static_cast<float>(std::max(0.0, 1.0 - d2 / (R * R)));
    };
    // Stored: the bricks the ball reaches, as the density volume stores them.
    const auto reaches = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        for (std::uint32_t k = 0; k < kBrickEdge; ++k) {
            for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
                for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                    if (ball(g.x(a * kBrickCells + i), g.y(b * kBrickCells + j), g.z(c * kBrickCells + k)) >
                        0) {
                        return true;
                    }
                }
            }
        }
        return false;
    };
    const HandVolume hand(g, iso, reaches, ball);
    ASSERT_GT(hand.stored(), 0u);
    ASSERT_LT(hand.stored(), g.bricks());
    const std::string path = test::temp_path("ball.vdb");
    VdbWriteSettings options;
    options.level_set = true;
    write_vdb(path, hand.view(), options);

    const openvdb::GridPtrVecPtr grids = read_grids(path);
    ASSERT_EQ(grids->size(), 2u);
    ASSERT_TRUE(float_grid(grids, "density"));
    const openvdb::FloatGrid::Ptr surface = float_grid(grids, "surface");
    ASSERT_TRUE(surface);
    EXPECT_EQ(surface->getGridClass(), openvdb::GRID_LEVEL_SET);
    const float band = options.half_width * g.voxel;
    EXPECT_NEAR(surface->background(), band, 1e-6f);
    expect_lattice_transform(*surface, g);
    expect_rivulet_metadata(*surface, iso);

    const double rs = R * std::sqrt(1.0 - iso);
    const auto acc = surface->getConstAccessor();
    const auto distance = [&](const openvdb::Coord& ijk) {
        const openvdb::Vec3d p = surface->indexToWorld(ijk);
        return std::sqrt((p.x() - cx) * (p.x() - cx) + (p.y() - cy) * (p.y() - cy) +
                         (p.z() - cz) * (p.z() - cz)) -
               rs;
    };
    // The centre, deeper than the band, reads the interior background; far outside the exterior one.
    const openvdb::Coord centre(10, 8, 8);
    ASSERT_NEAR(distance(centre), -rs, 1e-6);
    EXPECT_LT(acc.getValue(centre), 0.0f);
    EXPECT_FLOAT_EQ(acc.getValue(centre), -surface->background());
    EXPECT_FLOAT_EQ(acc.getValue(openvdb::Coord(22, 8, 8)), surface->background());

    // Every lattice point: negative inside and positive outside the sphere, and within the band the
    // distance itself. Marching cubes interpolates F linearly between samples, so the mesh, and with it
    // the distance, is off by far less than a voxel.
    double worst = 0;
    int near_surface = 0;
    for (std::int32_t k = 0; k < std::int32_t(g.samples_z()); ++k) {
        for (std::int32_t j = 0; j < std::int32_t(g.samples_y()); ++j) {
            for (std::int32_t i = 0; i < std::int32_t(g.samples_x()); ++i) {
                const openvdb::Coord ijk(i, j, k);
                const double d = distance(ijk);
                const float v = acc.getValue(ijk);
                if (d < -0.5 * g.voxel) {
                    ASSERT_LT(v, 0.0f) << ijk << " d " << d;
                }
                if (d > 0.5 * g.voxel) {
                    ASSERT_GT(v, 0.0f) << ijk << " d " << d;
                }
                if (std::abs(d) < 2.0 * g.voxel) {
                    ++near_surface;
                    ASSERT_TRUE(acc.isValueOn(ijk)) << ijk;
                    worst = std::max(worst, std::abs(v - d));
                }
            }
        }
    }
    EXPECT_GT(near_surface, 100);
    EXPECT_LT(worst, 0.3 * g.voxel) << "worst " << worst / g.voxel << " voxel";
}

TEST(VdbWriter, EmptyVolumeWritesEmptyGrids) {
    const DensityGrid g = small_grid(0, 0, 0, 0.2f);
    const HandVolume hand(
        g, 0.5f, [](std::uint32_t, std::uint32_t, std::uint32_t) { return false; },
        [](float, float, float) { return 0.0f; });
    const std::string path = test::temp_path("empty.vdb");
    VdbWriteSettings options;
    options.level_set = true;
    options.half_width = 2.5f;
    write_vdb(path, hand.view(), options);
    const openvdb::GridPtrVecPtr grids = read_grids(path);
    ASSERT_EQ(grids->size(), 2u);
    const openvdb::FloatGrid::Ptr density = float_grid(grids, "density"),
                                  surface = float_grid(grids, "surface");
    ASSERT_TRUE(density && surface);
    EXPECT_EQ(density->activeVoxelCount(), 0u);
    EXPECT_EQ(surface->activeVoxelCount(), 0u);
    EXPECT_EQ(surface->getGridClass(), openvdb::GRID_LEVEL_SET);
    EXPECT_NEAR(surface->background(), 2.5f * 0.2f, 1e-6f);
}

// The message must start with the path, as every file error in the project does.
void expect_write_error(const std::string& path, const DensityVolumeView& view,
                        const VdbWriteSettings& options = {}) {
    try {
        write_vdb(path, view, options);
        ADD_FAILURE() << "no error writing " << path;
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()).rfind(path, 0), 0u) << e.what();
    }
}

TEST(VdbWriter, UnwritablePathThrowsNamingIt) {
    const DensityGrid g = small_grid(0, 0, 0, 0.1f);
    const HandVolume hand(
        g, 0.5f, [](std::uint32_t a, std::uint32_t, std::uint32_t) { return a == 1; },
        [](float x, float, float) { return x; });
    expect_write_error(test::temp_path("no-such-dir") + "/out.vdb", hand.view());
    // A full disk: the write fails after the open succeeded, and the device is not removed.
    if (std::filesystem::exists("/dev/full")) {
        expect_write_error("/dev/full", hand.view());
        EXPECT_TRUE(std::filesystem::exists("/dev/full"));
    }
}

TEST(VdbWriter, MalformedVolumeThrowsBeforeWriting) {
    const DensityGrid g = small_grid(0, 0, 0, 0.1f);
    const HandVolume hand(
        g, 0.5f, [](std::uint32_t a, std::uint32_t, std::uint32_t) { return a != 1; },
        [](float x, float, float) { return x; });
    const std::string path = test::temp_path("malformed.vdb");

    DensityVolumeView short_atlas = hand.view();
    short_atlas.atlas = short_atlas.atlas.first(short_atlas.atlas.size() - 1);
    expect_write_error(path, short_atlas);

    DensityVolumeView bad_voxel = hand.view();
    bad_voxel.grid.voxel = 0;
    expect_write_error(path, bad_voxel);

    const std::vector<std::uint32_t> swapped = {hand.view().slot_brick[1], hand.view().slot_brick[0]};
    DensityVolumeView disagree = hand.view();
    disagree.slot_brick = std::span<const std::uint32_t>(swapped).first(2);
    disagree.slot_min = disagree.slot_min.first(2);
    disagree.slot_max = disagree.slot_max.first(2);
    expect_write_error(path, disagree);

    VdbWriteSettings thin;
    thin.level_set = true;
    thin.half_width = 0.5f;
    expect_write_error(path, hand.view(), thin);
    EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace rivulet
