#include "systems/render/camera.h"

#include <cmath>
#include <numbers>

namespace rivulet {

CameraBasis camera_basis(const CameraDesc& camera) {
    CameraBasis b;
    b.eye = camera.eye;
    b.forward = normalize(camera.target - camera.eye);
    // Looking (almost) straight up or down leaves +y no sideways direction; any horizontal axis will do.
    const Vec3f world_up = std::abs(b.forward.y) > 0.999f ? Vec3f{0, 0, -1} : Vec3f{0, 1, 0};
    b.right = normalize(cross(b.forward, world_up));
    b.up = cross(b.right, b.forward);
    b.tan_half_fov_y = std::tan(camera.fov_y_deg * (std::numbers::pi_v<float> / 360.0f));
    return b;
}

Mat4 look_at(const CameraBasis& b) {
    const Vec3f r = b.right, u = b.up, f = b.forward;
    Mat4 v;
    v << r.x, r.y, r.z, -dot(r, b.eye),   //
        u.x, u.y, u.z, -dot(u, b.eye),    //
        -f.x, -f.y, -f.z, dot(f, b.eye),  //
        0, 0, 0, 1;
    return v;
}

Mat4 perspective(float tan_half_fov_y, float aspect) {
    const float f = 1.0f / tan_half_fov_y;
    const float n = kCameraNear, fa = kCameraFar;
    Mat4 p;
    p << f / aspect, 0, 0, 0,                              //
        0, f, 0, 0,                                        //
        0, 0, (fa + n) / (n - fa), 2 * fa * n / (n - fa),  //
        0, 0, -1, 0;
    return p;
}

Mat4 view_projection(const CameraDesc& camera, float aspect) {
    const CameraBasis b = camera_basis(camera);
    return perspective(b.tan_half_fov_y, aspect) * look_at(b);
}

bool project_to_pixel(const CameraDesc& camera, int width, int height, Vec3f world, float& px, float& py) {
    const Mat4 vp = view_projection(camera, static_cast<float>(width) / static_cast<float>(height));
    const Eigen::Vector4f clip = clip_of(vp, world);
    if (clip[3] <= 0) return false;
    const float nx = clip[0] / clip[3], ny = clip[1] / clip[3], nz = clip[2] / clip[3];
    px = (nx * 0.5f + 0.5f) * static_cast<float>(width);
    py = (0.5f - ny * 0.5f) * static_cast<float>(height);
    return nz >= -1 && nz <= 1 && px >= 0 && px < static_cast<float>(width) && py >= 0 &&
           py < static_cast<float>(height);
}

}  // namespace rivulet
