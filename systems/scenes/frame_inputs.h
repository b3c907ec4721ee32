#pragma once
// What changes a running simulation from outside, frame by frame: a user dragging the container, a
// script opening or closing the emitters. Everything else of a frame follows from the scene and its
// seed, so a run is reproduced by its scene plus these inputs (recordings store them per frame).
#include <cstdint>

#include "jobs/vec3.h"
#include "systems/scenes/scene.h"

namespace rivulet {

struct FrameInputs {
    Vec3f container_offset;   // displacement of the fluid container from its rest pose (SPH scenes)
    float emitter_scale = 1;  // multiplies every emitter's rate (stream scenes)
};

inline bool operator==(const FrameInputs& a, const FrameInputs& b) {
    return a.container_offset.x == b.container_offset.x && a.container_offset.y == b.container_offset.y &&
           a.container_offset.z == b.container_offset.z && a.emitter_scale == b.emitter_scale;
}

// The inputs a scene scripts for itself: its container motion (offset = amplitude * sin(2 pi f t) at the
// frame's end, t = (frame + 1) * dt) and emitters always open.
FrameInputs scripted_inputs(const SceneDesc& scene, std::uint64_t frame);

}  // namespace rivulet
