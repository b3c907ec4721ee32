#include "systems/io/vdb_writer.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/LevelSetRebuild.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <vector>

#include "systems/io/input_file.h"

namespace rivulet {
namespace {

using Leaf = openvdb::FloatTree::LeafNodeType;
// A brick's samples [8a, 8a + 8) per axis are then exactly the leaf at origin 8a: bricks become leaves
// by a copy, and only the far faces (shared with the next bricks) need the tree's accessor.
static_assert(Leaf::DIM == kBrickCells);

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw FileFormatError(path + ": cannot write OpenVDB file: " + what);
}

struct BrickPos {
    std::uint32_t a, b, c;
};

BrickPos brick_pos(const DensityGrid& g, std::uint32_t brick) {
    return {brick % g.bx, (brick / g.bx) % g.by, brick / (g.bx * g.by)};
}

// Checked before the file is opened, so a malformed view never leaves a file behind.
void validate(const std::string& path, const DensityVolumeView& v, const VdbWriteSettings& options) {
    const DensityGrid& g = v.grid;
    if (!(g.voxel > 0.0f) || !std::isfinite(g.voxel)) fail(path, "voxel size is not positive and finite");
    if (!std::isfinite(g.ox) || !std::isfinite(g.oy) || !std::isfinite(g.oz)) {
        fail(path, "lattice origin is not finite");
    }
    if (!std::isfinite(v.iso)) fail(path, "iso value is not finite");
    if (options.level_set && !(options.half_width >= 1.0f && std::isfinite(options.half_width))) {
        fail(path, "level set half width must be at least one voxel");
    }
    // OpenVDB indexes voxels with 32-bit signed coordinates.
    constexpr std::uint32_t kMaxBricks = (std::uint32_t(INT32_MAX) - 1) / kBrickCells;
    if (g.bx > kMaxBricks || g.by > kMaxBricks || g.bz > kMaxBricks) fail(path, "lattice too large");
    const std::uint64_t bricks = std::uint64_t(g.bx) * g.by * g.bz;
    if (v.brick_slot.size() != bricks) {
        fail(path, "brick_slot has " + std::to_string(v.brick_slot.size()) + " entries for " +
                       std::to_string(bricks) + " bricks");
    }
    const std::size_t slots = v.slot_brick.size();
    if (slots > bricks) fail(path, "more stored bricks than bricks");
    const std::size_t need = atlas_samples(atlas_layers(static_cast<std::uint32_t>(slots)));
    if (v.atlas.size() < need) {
        fail(path, "atlas has " + std::to_string(v.atlas.size()) + " samples, " + std::to_string(slots) +
                       " stored bricks need " + std::to_string(need));
    }
    for (std::size_t s = 0; s < slots; ++s) {
        const std::uint32_t brick = v.slot_brick[s];
        if (brick >= bricks || v.brick_slot[brick] != static_cast<std::int32_t>(s)) {
            fail(path, "slot " + std::to_string(s) + " and brick_slot disagree");
        }
    }
}

// The leaf at the brick's origin: its samples [0, 8) per axis, all active.
std::unique_ptr<Leaf> brick_leaf(const DensityVolumeView& v, std::uint32_t slot) {
    const BrickPos p = brick_pos(v.grid, v.slot_brick[slot]);
    const openvdb::Coord origin(static_cast<openvdb::Int32>(p.a * kBrickCells),
                                static_cast<openvdb::Int32>(p.b * kBrickCells),
                                static_cast<openvdb::Int32>(p.c * kBrickCells));
    auto leaf = std::make_unique<Leaf>(origin, 0.0f, /*active=*/true);
    float* dst = leaf->buffer().data();
    // The leaf is z-fastest, the atlas x-fastest: reading the atlas in order keeps its rows whole.
    for (std::uint32_t k = 0; k < kBrickCells; ++k) {
        for (std::uint32_t j = 0; j < kBrickCells; ++j) {
            const float* src = &v.atlas[atlas_offset(slot, 0, j, k)];
            for (std::uint32_t i = 0; i < kBrickCells; ++i)
                dst[(i * kBrickCells + j) * kBrickCells + k] = src[i];
        }
    }
    return leaf;
}

openvdb::FloatGrid::Ptr density_grid(const DensityVolumeView& v) {
    const DensityGrid& g = v.grid;
    auto grid = openvdb::FloatGrid::create(0.0f);
    auto xform = openvdb::math::Transform::createLinearTransform(double(g.voxel));
    xform->postTranslate(openvdb::Vec3d(double(g.ox), double(g.oy), double(g.oz)));
    grid->setTransform(xform);

    // Leaves are filled in parallel (the copy is the whole cost) and linked into the tree afterwards,
    // which only touches pointers.
    const std::size_t slots = v.slot_brick.size();
    std::vector<std::unique_ptr<Leaf>> leaves(slots);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slots, 16),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t s = r.begin(); s != r.end(); ++s)
                              leaves[s] = brick_leaf(v, static_cast<std::uint32_t>(s));
                      });
    auto& tree = grid->tree();
    for (auto& leaf : leaves) tree.addLeaf(leaf.release());

    // A far-face sample lies in the leaf of the next brick along that axis; where that brick is stored its
    // own copy (the same value) is already there, elsewhere this brick's copy is the only one.
    const auto stored = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
        return a < g.bx && b < g.by && c < g.bz && v.brick_slot[g.brick_index(a, b, c)] >= 0;
    };
    auto accessor = grid->getAccessor();
    for (std::size_t s = 0; s < slots; ++s) {
        const BrickPos p = brick_pos(g, v.slot_brick[s]);
        bool owner_stored[8] = {true};  // by (i == 8) | (j == 8) << 1 | (k == 8) << 2
        bool all_stored = true;
        for (std::uint32_t n = 1; n < 8; ++n) {
            owner_stored[n] = stored(p.a + (n & 1), p.b + ((n >> 1) & 1), p.c + (n >> 2));
            all_stored = all_stored && owner_stored[n];
        }
        if (all_stored) continue;
        const auto slot = static_cast<std::uint32_t>(s);
        for (std::uint32_t k = 0; k < kBrickEdge; ++k) {
            for (std::uint32_t j = 0; j < kBrickEdge; ++j) {
                for (std::uint32_t i = 0; i < kBrickEdge; ++i) {
                    const std::uint32_t n = std::uint32_t(i == kBrickCells) |
                                            std::uint32_t(j == kBrickCells) << 1 |
                                            std::uint32_t(k == kBrickCells) << 2;
                    if (n == 0 || owner_stored[n]) continue;
                    const openvdb::Coord ijk(static_cast<openvdb::Int32>(p.a * kBrickCells + i),
                                             static_cast<openvdb::Int32>(p.b * kBrickCells + j),
                                             static_cast<openvdb::Int32>(p.c * kBrickCells + k));
                    accessor.setValue(ijk, v.atlas[atlas_offset(slot, i, j, k)]);
                }
            }
        }
    }
    return grid;
}

// io::File::write closes its stream without looking at the result, so a full disk would go unnoticed:
// this writes the same seekable archive into a stream whose state we check.
class ArchiveWriter : public openvdb::io::Archive {
  public:
    void save(std::ostream& out, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) const {
        Archive::write(out, grids, /*seekable=*/true, meta);
    }
};

void save(const std::string& path, const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& meta) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out) fail(path, "cannot open for writing: " + io::errno_message(errno));
    // Only a regular file is removed on failure, never a device such as /dev/full.
    std::error_code ec;
    const bool regular = std::filesystem::is_regular_file(path, ec);
    const auto give_up = [&](const std::string& what) {
        out.close();
        if (regular) std::filesystem::remove(path, ec);
        fail(path, what);
    };
    errno = 0;
    try {
        ArchiveWriter().save(out, grids, meta);
    } catch (const openvdb::Exception& e) {
        give_up(e.what());
    }
    if (!out.flush()) give_up(errno ? "write failed: " + io::errno_message(errno) : "write failed");
    out.close();
    if (out.fail()) give_up("write failed on close");
}

}  // namespace

void write_vdb(const std::string& path, const DensityVolumeView& volume, const VdbWriteSettings& options) {
    static std::once_flag initialized;
    std::call_once(initialized, [] { openvdb::initialize(); });
    validate(path, volume, options);

    openvdb::GridCPtrVec grids;
    const auto tag = [&](openvdb::GridBase& grid, const char* name, openvdb::GridClass cls) {
        grid.setName(name);
        grid.setGridClass(cls);
        grid.setCreator("rivulet");
        grid.insertMeta("iso", openvdb::FloatMetadata(volume.iso));
    };
    try {
        const openvdb::FloatGrid::Ptr density = density_grid(volume);
        tag(*density, "density", openvdb::GRID_FOG_VOLUME);
        grids.push_back(density);
        if (options.level_set) {
            // Meshes F = iso and scan-converts the mesh. The sign comes from the closed mesh's inside
            // and outside, not from the values, so the fluid comes out negative as a level set wants
            // although F is the larger there. The background is half_width voxels in world units.
            const openvdb::FloatGrid::Ptr surface =
                openvdb::tools::levelSetRebuild(*density, volume.iso, options.half_width, options.half_width);
            tag(*surface, "surface", openvdb::GRID_LEVEL_SET);
            grids.push_back(surface);
        }
    } catch (const openvdb::Exception& e) {
        fail(path, e.what());
    }
    openvdb::MetaMap meta;
    meta.insertMeta("creator", openvdb::StringMetadata("rivulet"));
    save(path, grids, meta);
}

}  // namespace rivulet
