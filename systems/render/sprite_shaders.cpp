#include "systems/render/sprite_shaders.h"

namespace rivulet::shaders {

// clip.w is the depth along the view direction, so a world-space diameter spans size * P[1][1] / w of
// the [-1, 1] NDC height: u_pixels_per_unit = viewport_height * P[1][1] / 2. Points narrower than a pixel
// are drawn one pixel wide and fade by their area instead, so distant particles thin out rather than
// stay as bright specks. A transparent sprite (a particle that died this frame) is put outside the clip
// volume: it would add nothing to any pixel, and this way it is not rasterized either.
const char* const kDiffuseSpriteVertex = R"(#version 450 core
layout(location = 0) in vec4 a_center_size;
layout(location = 1) in vec4 a_color;
uniform mat4 u_view_proj;
uniform float u_pixels_per_unit;
uniform float u_max_point_size;
out vec4 v_color;
void main() {
    vec4 clip = u_view_proj * vec4(a_center_size.xyz, 1.0);
    gl_Position = a_color.a > 0.0 ? clip : vec4(2.0, 2.0, 2.0, 1.0);
    float pixels = clip.w > 0.0 ? a_center_size.w * u_pixels_per_unit / clip.w : 0.0;
    gl_PointSize = clamp(pixels, 1.0, u_max_point_size);
    float fade = min(pixels * pixels, 1.0);
    v_color = vec4(a_color.rgb * a_color.a, a_color.a) * fade;
}
)";

// (1 - r^2)^2 falls smoothly to zero at the rim with zero slope, so overlapping sprites blend without
// visible edges; premultiplied output serves both the "over" and the additive blend unchanged.
const char* const kDiffuseSpriteFragment = R"(#version 450 core
in vec4 v_color;
out vec4 frag_color;
void main() {
    vec2 q = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(q, q);
    if (r2 > 1.0) discard;
    float w = 1.0 - r2;
    frag_color = v_color * (w * w);
}
)";

}  // namespace rivulet::shaders
