#include "tests/fuzz/harness.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <span>
#include <vector>

namespace rivulet::fuzz {
namespace {

bool same_bits(std::span<const float> a, std::span<const float> b) {
    return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size_bytes()) == 0);
}

}  // namespace

const std::string& scratch_dir() {
    // /dev/shm keeps millions of write-then-read iterations off the disk. run_fuzzers.sh points
    // RIVULET_FUZZ_SCRATCH at a folder it removes afterwards, since a crashing process skips atexit.
    // Never destroyed: its destructor would run before the atexit handler below, which needs the path.
    static const std::string& dir = *new std::string([] {
        std::error_code ec;
        const char* env = std::getenv("RIVULET_FUZZ_SCRATCH");
        const std::filesystem::path base = env != nullptr && *env != '\0' ? std::filesystem::path(env)
                                           : std::filesystem::is_directory("/dev/shm", ec)
                                               ? std::filesystem::path("/dev/shm")
                                               : std::filesystem::temp_directory_path();
        const std::filesystem::path d = base / ("rivulet-fuzz-" + std::to_string(::getpid()));
        std::filesystem::create_directories(d, ec);
        if (ec) finding("cannot create the scratch folder " + d.string() + ": " + ec.message());
        std::atexit([] {
            std::error_code ignored;
            std::filesystem::remove_all(scratch_dir(), ignored);
        });
        return d.string();
    }());
    return dir;
}

std::string write_scratch(std::string_view name, const std::uint8_t* data, std::size_t size) {
    std::string path = scratch_dir() + "/" + std::string(name);
    std::FILE* f = std::fopen(path.c_str(), "wb");
    const bool ok = f != nullptr && (size == 0 || std::fwrite(data, 1, size, f) == size);
    if (f != nullptr && std::fclose(f) != 0 && ok) finding("cannot close " + path);
    if (!ok) finding("cannot write " + path);
    return path;
}

void finding(const std::string& what) {
    std::fprintf(stderr, "fuzz finding: %s\n", what.c_str());
    std::fflush(stderr);
    std::abort();
}

void check_particles_round_trip(const ParticleCloud& cloud) {
    const std::string path = scratch_dir() + "/round_trip.ply";
    write_particles_ply(path, cloud.x, cloud.y, cloud.z);
    const ParticleCloud back = read_particles(path);
    if (!same_bits(cloud.x, back.x) || !same_bits(cloud.y, back.y) || !same_bits(cloud.z, back.z))
        finding("particles written by write_particles_ply read back differently");
}

void check_mesh_round_trip(const MeshData& mesh, std::string_view extension) {
    const std::string path = scratch_dir() + "/round_trip" + std::string(extension);
    write_mesh(path, mesh.vertices6, mesh.indices);
    const MeshData back = read_mesh(path);
    // In an OBJ file with faces a normal reaches a vertex through the faces that use it ("f a//a"), so a
    // vertex no triangle uses reads back with a zero normal: the format as written, not a finding.
    std::vector<float> expected = mesh.vertices6;
    if (extension == ".obj" && !mesh.indices.empty()) {
        std::vector<bool> used(mesh.vertex_count(), false);
        for (const std::uint32_t i : mesh.indices) used[i] = true;
        for (std::size_t v = 0; v < used.size(); ++v) {
            if (!used[v]) std::fill_n(expected.begin() + std::ptrdiff_t(6 * v + 3), 3, 0.0f);
        }
    }
    if (!same_bits(expected, back.vertices6) || mesh.indices != back.indices)
        finding("a mesh written by write_mesh as " + std::string(extension) + " reads back differently");
}

int bracket_depth(std::string_view text) {
    int depth = 0, deepest = 0;
    for (const char c : text) {
        if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

}  // namespace rivulet::fuzz
