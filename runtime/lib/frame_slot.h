#pragma once
// One of the two frame slots (DESIGN §1): everything the render thread needs of a frame, written by the
// workers while the other slot is being drawn. Never read and written at once: the hand-over is the
// frame graph's wait().
#include <cstdint>

#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"
#include "systems/scan/scan_output.h"
#include "systems/scenes/frame_inputs.h"
#include "systems/slices/surface_mesh.h"

namespace rivulet {

struct FrameSlot {
    std::uint64_t frame = 0;
    std::uint32_t particles = 0;
    ScanOutput scan;   // sphere scan conversion
    SurfaceMesh mesh;  // marching slices
    AlignedArray<float> pool_heights;
    HeightFieldView pool;
    std::uint64_t hash = 0;           // frame_output_hash, when hashing is on
    std::uint64_t particle_hash = 0;  // idem, of the particle arrays
    FrameInputs inputs;

    FrameView view(float sphere_radius) const {
        FrameView v;
        v.cylinders = scan.cylinder_view();
        v.sphere_centers = scan.sphere_view();
        v.mesh = mesh.view();
        v.sphere_radius = sphere_radius;
        v.pool = pool;
        return v;
    }
};

}  // namespace rivulet
