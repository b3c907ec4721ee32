// PLY meshes: ascii, binary little and big endian; vertex positions, optional normals, face lists.
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("input.ply", data, size);
    if (const auto mesh = rivulet::fuzz::read_or_reject([&] { return rivulet::read_mesh(path); }))
        rivulet::fuzz::check_mesh_round_trip(*mesh, ".ply");
    return 0;
}
