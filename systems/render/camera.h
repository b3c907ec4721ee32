#pragma once
// Pinhole camera of a scene: the matrices the renderer draws with, and the same projection for tests
// that need to know where a world point lands in a rendered picture.
#include <Eigen/Core>

#include "jobs/vec3.h"
#include "systems/scenes/scene.h"

namespace rivulet {

// Column-major, as glUniformMatrix4fv takes it with transpose = GL_FALSE (pass .data()).
using Mat4 = Eigen::Matrix4f;

// Homogeneous clip coordinates of a world point under `m`.
inline Eigen::Vector4f clip_of(const Mat4& m, Vec3f p) {
    return m * Eigen::Vector4f(p.x, p.y, p.z, 1.0f);
}

inline constexpr float kCameraNear = 0.05f;
inline constexpr float kCameraFar = 100.0f;

// Orthonormal view basis (+y up unless the camera looks straight along it).
struct CameraBasis {
    Vec3f eye, forward, right, up;
    float tan_half_fov_y = 1;
};

CameraBasis camera_basis(const CameraDesc& camera);
// World -> view: the basis as rows, the eye at the origin, looking down -z (OpenGL's convention).
Mat4 look_at(const CameraBasis& basis);
// View -> clip: OpenGL's perspective matrix over [kCameraNear, kCameraFar].
Mat4 perspective(float tan_half_fov_y, float aspect);
Mat4 view_projection(const CameraDesc& camera, float aspect);

// Pixel coordinates of `world` in a width x height picture, px from the left, py from the TOP row (the
// row order of Renderer::read_rgba); pixel (i, j) covers [i, i+1) x [j, j+1). False when the point is
// behind the camera, outside the near/far range or outside the picture.
bool project_to_pixel(const CameraDesc& camera, int width, int height, Vec3f world, float& px, float& py);

}  // namespace rivulet
