#include <algorithm>
#include <vector>

#include "systems/io/byte_order.h"
#include "systems/io/mesh_formats.h"
#include "systems/io/output_file.h"

namespace rivulet::io {

void write_ply_mesh(const std::string& path, std::span<const float> v6, std::span<const std::uint32_t> idx) {
    const std::size_t nv = v6.size() / 6, nt = idx.size() / 3;
    OutputFile out(path);
    out.write("ply\nformat binary_little_endian 1.0\ncomment written by Rivulet\nelement vertex " +
              std::to_string(nv) +
              "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\n"
              "property float nz\nelement face " +
              std::to_string(nt) + "\nproperty list uchar uint vertex_indices\nend_header\n");

    constexpr std::size_t kChunk = 64 * 1024;
    std::vector<std::byte> buf(kChunk * 24);
    for (std::size_t first = 0; first < nv; first += kChunk) {
        const std::size_t count = std::min(kChunk, nv - first);
        for (std::size_t i = 0; i < 6 * count; ++i) store_f32_le(buf.data() + 4 * i, v6[6 * first + i]);
        out.write(buf.data(), 24 * count);
    }
    for (std::size_t first = 0; first < nt; first += kChunk) {
        const std::size_t count = std::min(kChunk, nt - first);
        for (std::size_t t = 0; t < count; ++t) {
            std::byte* rec = buf.data() + 13 * t;
            rec[0] = std::byte{3};
            for (std::size_t k = 0; k < 3; ++k) store_u32_le(rec + 1 + 4 * k, idx[3 * (first + t) + k]);
        }
        out.write(buf.data(), 13 * count);
    }
    out.commit();
}

}  // namespace rivulet::io
