#include <algorithm>
#include <vector>

#include "systems/io/byte_order.h"
#include "systems/io/output_file.h"
#include "systems/io/particle_io.h"

namespace rivulet {

void write_particles_ply(const std::string& path, std::span<const float> x, std::span<const float> y,
                         std::span<const float> z) {
    if (x.size() != y.size() || x.size() != z.size()) {
        throw FileFormatError(path + ": cannot write particles: x, y, z have different lengths (" +
                              std::to_string(x.size()) + ", " + std::to_string(y.size()) + ", " +
                              std::to_string(z.size()) + ")");
    }
    io::OutputFile out(path);
    out.write("ply\nformat binary_little_endian 1.0\ncomment written by Rivulet\nelement vertex " +
              std::to_string(x.size()) +
              "\nproperty float x\nproperty float y\nproperty float z\nend_header\n");
    constexpr std::size_t kChunk = 64 * 1024;
    std::vector<std::byte> buf(std::min(kChunk, x.size()) * 12);
    for (std::size_t first = 0; first < x.size(); first += kChunk) {
        const std::size_t count = std::min(kChunk, x.size() - first);
        for (std::size_t i = 0; i < count; ++i) {
            std::byte* rec = buf.data() + 12 * i;
            io::store_f32_le(rec, x[first + i]);
            io::store_f32_le(rec + 4, y[first + i]);
            io::store_f32_le(rec + 8, z[first + i]);
        }
        out.write(buf.data(), count * 12);
    }
    out.commit();
}

}  // namespace rivulet
