// Legacy VTK particles: POLYDATA or UNSTRUCTURED_GRID, ascii or binary (only POINTS is read).
#include "tests/fuzz/harness.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = rivulet::fuzz::write_scratch("input.vtk", data, size);
    if (const auto cloud = rivulet::fuzz::read_or_reject([&] { return rivulet::read_particles(path); }))
        rivulet::fuzz::check_particles_round_trip(*cloud);
    return 0;
}
