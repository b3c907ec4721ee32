#pragma once
// The marching-slices scalar field (Janisz §3.2.1, eq. 3.4-3.5) and the global corner grid it is
// sampled on. Header-only so the extractor and the test oracle evaluate bit-identical values.
//
//   F(p) = sum over particles s with |s - p| < R_c of f(|s - p|),
//   f(r) = (r / (sqrt(2) R_c))^4 - (r / (sqrt(2) R_c))^2 + 0.25 = (q - 1/2)^2 with q = r^2 / (2 R_c^2),
//
// which falls monotonically from 0.25 at the centre to 0 at R_c. Inside the fluid is F >= iso.
#include <cmath>
#include <cstdint>
#include <stdexcept>

namespace rivulet {

// Limits SlicesSettings::validate enforces: the sweep's stack arrays hold a block edge of corners, and the
// lookup cache packs a particle's covered columns into bytes and its reach box's first row into 16 bits.
inline constexpr std::uint32_t kMaxBlockCubes = 128;
inline constexpr std::int32_t kMaxReach = 128;  // R_c / voxel

struct SliceKernel {
    float rc2 = 1;         // R_c^2
    float inv_2rc2 = 0.5;  // 1 / (2 R_c^2)

    static SliceKernel from_rc(float rc) { return {rc * rc, 1.0f / (2.0f * rc * rc)}; }
    // f at squared distance r2 (zero at and beyond R_c).
    float operator()(float r2) const {
        if (!(r2 < rc2)) return 0.0f;
        const float q = r2 * inv_2rc2 - 0.5f;
        return q * q;
    }
};

// The corner lattice shared by every block: corner (i, j, k) lies at origin + voxel * (i, j, k), computed
// the same way everywhere so corners on a block border get identical positions in both blocks.
struct SliceGrid {
    float ox = 0, oy = 0, oz = 0;  // corner (0, 0, 0)
    float voxel = 1;               // set both with set_voxel
    float inv_voxel = 1;           // 1 / voxel, for cell()
    float rc = 1;
    std::uint32_t n = 16;                            // cubes per block edge (set with set_block_cubes)
    std::uint64_t n_magic = std::uint64_t(1) << 28;  // ceil(2^32 / n)
    std::uint32_t bx = 0, by = 0, bz = 0;            // blocks per axis
    // Conservative reach of one particle in corners: every corner within R_c of it lies in
    // [cell(p) - reach, cell(p) + reach + 1] (test CellsByAMultiplyStayWithinOneOfFloorAnd...).
    std::int32_t reach = 1;

    void set_voxel(float v) {
        voxel = v;
        inv_voxel = 1.0f / v;
    }
    // Throws std::invalid_argument outside [2, kMaxBlockCubes] (SlicesSettings::validate's range).
    void set_block_cubes(std::uint32_t cubes) {
        if (cubes < 2 || cubes > kMaxBlockCubes)
            throw std::invalid_argument("marching slices: block edge outside [2, 128] cubes");
        n = cubes;
        n_magic = ((std::uint64_t(1) << 32) + cubes - 1) / cubes;
    }
    // c / n for corner indices c < 2^21 by a multiply: ceil(2^32 / n) is exact there for n <= 128 (the
    // error c (magic n - 2^32) / (n 2^32) < 2^21 n / (n 2^32) stays below 1 / n); a 32-bit division by a
    // runtime n costs more than the rest of the callers' work.
    std::uint32_t block_of(std::uint32_t c) const { return static_cast<std::uint32_t>((c * n_magic) >> 32); }

    float cx(std::int32_t i) const { return ox + voxel * static_cast<float>(i); }
    float cy(std::int32_t j) const { return oy + voxel * static_cast<float>(j); }
    float cz(std::int32_t k) const { return oz + voxel * static_cast<float>(k); }
    std::uint32_t blocks() const { return bx * by * bz; }
    std::uint32_t corners_x() const { return bx * n + 1; }
    std::uint32_t corners_y() const { return by * n + 1; }
    std::uint32_t corners_z() const { return bz * n + 1; }
    // The cube (slab) index of coordinate p along one axis: floor((p - o) / voxel), with the quotient as
    // a product by 1 / voxel (a division costs several times a multiply, and cells are computed several
    // times per particle and block). That can round a coordinate within an ulp of a corner plane into the
    // cube on the plane's other side, which moves nothing that matters: every user of cells allows a
    // corner of margin for rounding (the reach, the grid's padding), and all of them, the test oracle's
    // summation order included, call this one function. floor() by truncation and a correction: the same
    // integer as std::floor for |t| < 2^31, without the library call (x86-64 baseline has no SSE4.1 round
    // instruction).
    static std::int32_t cell(float p, float o, float inv_voxel) {
        const float t = (p - o) * inv_voxel;
        const auto i = static_cast<std::int32_t>(t);
        return i - (static_cast<float>(i) > t ? 1 : 0);
    }
};

// Global key of the cube edge starting at corner (i, j, k) along `axis` (0 x, 1 y, 2 z); keys are unique
// while every corner index stays below 2^21.
inline std::uint64_t edge_key(std::uint32_t i, std::uint32_t j, std::uint32_t k, std::uint32_t axis) {
    return ((std::uint64_t(k) << 42 | std::uint64_t(j) << 21 | std::uint64_t(i)) << 2) | axis;
}
inline void edge_key_corner(std::uint64_t key, std::uint32_t& i, std::uint32_t& j, std::uint32_t& k,
                            std::uint32_t& axis) {
    axis = static_cast<std::uint32_t>(key & 3u);
    const std::uint64_t c = key >> 2;
    i = static_cast<std::uint32_t>(c & 0x1fffffu);
    j = static_cast<std::uint32_t>((c >> 21) & 0x1fffffu);
    k = static_cast<std::uint32_t>(c >> 42);
}

// Vertex on the edge from corner a (value fa) to corner b = a + voxel along the axis (value fb); exactly
// one of fa, fb is >= iso. Returns the coordinate along the axis.
inline float edge_crossing(float a, float voxel, float fa, float fb, float iso) {
    const float t = (iso - fa) / (fb - fa);
    return a + t * voxel;
}

}  // namespace rivulet
