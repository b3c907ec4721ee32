#include "systems/scenes/frame_inputs.h"

#include <cmath>
#include <numbers>

namespace rivulet {

FrameInputs scripted_inputs(const SceneDesc& scene, std::uint64_t frame) {
    FrameInputs in;
    const ContainerMotion& m = scene.container_motion;
    if (m.frequency > 0) {
        // Where the container is at the end of the frame. Phase in double: the time grows without bound
        // and float would lose the sine's argument.
        const double t = double(frame + 1) * double(scene.dt);
        const float s = static_cast<float>(std::sin(2.0 * std::numbers::pi * double(m.frequency) * t));
        in.container_offset = m.amplitude * s;
    }
    return in;
}

}  // namespace rivulet
