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

Mat4 view_projection(const CameraDesc& camera, float aspect) {
    const CameraBasis b = camera_basis(camera);
    const float f = 1.0f / b.tan_half_fov_y;
    const float n = kCameraNear, fa = kCameraFar;
    // Rows of P * V with P the OpenGL perspective matrix and V the look-at matrix, written out directly.
    const float sx = f / aspect, sy = f;
    const float za = (fa + n) / (n - fa), zb = 2 * fa * n / (n - fa);
    const Vec3f r = b.right, u = b.up, fw = b.forward;
    const float tr = -dot(r, b.eye), tu = -dot(u, b.eye), tf = dot(fw, b.eye);
    Mat4 out{};
    auto set_row = [&](int row, float c0, float c1, float c2, float c3) {
        out.m[0 * 4 + row] = c0;
        out.m[1 * 4 + row] = c1;
        out.m[2 * 4 + row] = c2;
        out.m[3 * 4 + row] = c3;
    };
    // View-space z is -forward, so clip z = za * (-fw . p + tf) + zb and clip w = fw . p - tf.
    set_row(0, sx * r.x, sx * r.y, sx * r.z, sx * tr);
    set_row(1, sy * u.x, sy * u.y, sy * u.z, sy * tu);
    set_row(2, -za * fw.x, -za * fw.y, -za * fw.z, za * tf + zb);
    set_row(3, fw.x, fw.y, fw.z, -tf);
    return out;
}

bool project_to_pixel(const CameraDesc& camera, int width, int height, Vec3f world, float& px, float& py) {
    const Mat4 vp = view_projection(camera, static_cast<float>(width) / static_cast<float>(height));
    float clip[4];
    for (int row = 0; row < 4; ++row) {
        clip[row] = vp.m[row] * world.x + vp.m[4 + row] * world.y + vp.m[8 + row] * world.z + vp.m[12 + row];
    }
    if (clip[3] <= 0) return false;
    const float nx = clip[0] / clip[3], ny = clip[1] / clip[3], nz = clip[2] / clip[3];
    px = (nx * 0.5f + 0.5f) * static_cast<float>(width);
    py = (0.5f - ny * 0.5f) * static_cast<float>(height);
    return nz >= -1 && nz <= 1 && px >= 0 && px < static_cast<float>(width) && py >= 0 &&
           py < static_cast<float>(height);
}

}  // namespace rivulet
