#pragma once
// One of the two frame slots (DESIGN §1): what the render thread needs of a frame besides its surface
// (which the surface method keeps per slot), written by the workers while the other slot is being drawn.
// Never read and written at once: the hand-over is the frame graph's wait().
#include <cstdint>

#include "systems/particles/aligned_array.h"
#include "systems/render/frame_view.h"
#include "systems/scenes/frame_inputs.h"

namespace rivulet {

struct FrameSlot {
    std::uint64_t frame = 0;
    std::uint32_t particles = 0;
    AlignedArray<float> pool_heights;
    HeightFieldView pool;
    std::uint64_t hash = 0;           // frame_output_hash, when hashing is on
    std::uint64_t particle_hash = 0;  // idem, of the particle arrays
    FrameInputs inputs;

    // The slot's part of the render pass's view; the surface method fills in its own.
    FrameView view(float sphere_radius) const {
        FrameView v;
        v.sphere_radius = sphere_radius;
        v.pool = pool;
        return v;
    }
};

}  // namespace rivulet
