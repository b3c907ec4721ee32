#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

#include "systems/io/byte_order.h"
#include "systems/io/mesh_formats.h"
#include "systems/io/output_file.h"

namespace rivulet::io {
namespace {

// Writes one float triple per vertex (position or normal) in big-endian, as legacy VTK binary requires.
void write_triples(OutputFile& out, std::span<const float> v6, std::size_t component_offset) {
    constexpr std::size_t kChunk = 64 * 1024;
    const std::size_t nv = v6.size() / 6;
    std::vector<std::byte> buf(std::min(kChunk, nv) * 12);
    for (std::size_t first = 0; first < nv; first += kChunk) {
        const std::size_t count = std::min(kChunk, nv - first);
        for (std::size_t i = 0; i < count; ++i) {
            for (std::size_t k = 0; k < 3; ++k) {
                store_f32_be(buf.data() + 12 * i + 4 * k, v6[6 * (first + i) + component_offset + k]);
            }
        }
        out.write(buf.data(), 12 * count);
    }
}

}  // namespace

// Classic (pre-5.0) legacy layout, which every VTK/ParaView version reads; its cell arrays are signed
// 32-bit, hence the size limit.
void write_vtk_mesh(const std::string& path, std::span<const float> v6, std::span<const std::uint32_t> idx) {
    const std::size_t nv = v6.size() / 6, nt = idx.size() / 3;
    constexpr auto kMax = static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
    if (nv > kMax || nt > kMax / 4) {
        throw FileFormatError(path + ": cannot write mesh: too large for legacy VTK (32-bit cell arrays)");
    }
    OutputFile out(path);
    out.write("# vtk DataFile Version 3.0\nRivulet surface mesh\nBINARY\nDATASET POLYDATA\nPOINTS " +
              std::to_string(nv) + " float\n");
    write_triples(out, v6, 0);
    out.write("\n");
    if (nt > 0) {
        out.write("POLYGONS " + std::to_string(nt) + " " + std::to_string(4 * nt) + "\n");
        constexpr std::size_t kChunk = 64 * 1024;
        std::vector<std::byte> buf(std::min(kChunk, nt) * 16);
        for (std::size_t first = 0; first < nt; first += kChunk) {
            const std::size_t count = std::min(kChunk, nt - first);
            for (std::size_t t = 0; t < count; ++t) {
                store_u32_be(buf.data() + 16 * t, 3);
                for (std::size_t k = 0; k < 3; ++k)
                    store_u32_be(buf.data() + 16 * t + 4 + 4 * k, idx[3 * (first + t) + k]);
            }
            out.write(buf.data(), 16 * count);
        }
        out.write("\n");
    }
    if (nv > 0) {
        out.write("POINT_DATA " + std::to_string(nv) + "\nNORMALS normals float\n");
        write_triples(out, v6, 3);
        out.write("\n");
    }
    out.commit();
}

}  // namespace rivulet::io
