// OBJ meshes (v / vn / f).
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("input.obj", data, size);
    if (const auto mesh = rivulet::fuzz::read_or_reject([&] { return rivulet::read_mesh(path); }))
        rivulet::fuzz::check_mesh_round_trip(*mesh, ".obj");
    return 0;
}
