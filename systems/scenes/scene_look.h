#pragma once
// How a scene's water and surroundings look: the same for every surface method, so one frame rendered
// three ways differs only in its surface. Scene files choose them (docs/scenes.md).
#include <string>
#include <vector>

#include "jobs/vec3.h"

namespace rivulet {

struct WaterLook {
    Vec3f color{0.06f, 0.30f, 0.52f};    // what thick water tends to (linear RGB)
    Vec3f absorption{9.0f, 3.5f, 1.6f};  // Beer-Lambert coefficients per metre, per channel
};

// The environment reflected by the water and seen behind the scene: an empty list means the sky and
// floor made at start-up; else six images, in the order +x, -x, +y, -y, +z, -z.
struct EnvironmentDesc {
    std::vector<std::string> faces;
};

struct SceneLook {
    WaterLook water;
    EnvironmentDesc environment;
};

}  // namespace rivulet
