#pragma once
// Static obstacles of a scene, shared by every simulation (streams and SPH) and the renderer.
#include "jobs/vec3.h"

namespace rivulet {

struct SphereCollider {
    Vec3f center;
    float radius = 0;
};

struct BoxCollider {
    Vec3f min, max;
};

}  // namespace rivulet
