#include "systems/render/shaders.h"

namespace rivulet::shaders {

// A pale, barely blue sky: water has to stand out from the background in pictures and in the tests
// that tell them apart by colour.
const char* const kFragmentPrelude = R"(#version 450 core
const vec3 kHorizon = vec3(0.86, 0.88, 0.90);
const vec3 kZenith = vec3(0.70, 0.77, 0.85);
const vec3 kGroundBounce = vec3(0.55, 0.52, 0.47);
vec3 sky_color(vec3 dir) {
    if (dir.y < 0.0) return mix(kHorizon, kGroundBounce, clamp(-dir.y * 3.0, 0.0, 1.0));
    return mix(kHorizon, kZenith, sqrt(dir.y));
}
)";

const char* const kLitVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_offset;
uniform mat4 u_view_proj;
uniform float u_scale;
out vec3 v_world;
out vec3 v_normal;
void main() {
    v_world = a_position * u_scale + a_offset;
    v_normal = a_normal;
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
)";

const char* const kLitFragment = R"(
uniform vec3 u_eye;
uniform vec3 u_light_dir;
uniform int u_material;
in vec3 v_world;
in vec3 v_normal;
out vec4 frag_color;

vec3 shade_water(vec3 n, vec3 v) {
    const vec3 base = vec3(0.10, 0.43, 0.78);
    float ndl = max(dot(n, u_light_dir), 0.0);
    float ndv = max(dot(n, v), 0.0);
    // Schlick with water's F0; capped below 1 so silhouettes keep some body colour instead of
    // turning into the pale sky.
    float fresnel = 0.02 + 0.98 * pow(1.0 - ndv, 5.0);
    vec3 body = base * (0.35 + 0.65 * ndl);
    vec3 reflected = sky_color(reflect(-v, n));
    float spec = pow(max(dot(n, normalize(u_light_dir + v)), 0.0), 96.0);
    return mix(body, reflected, 0.6 * fresnel) + vec3(spec * (0.3 + 0.7 * fresnel));
}

vec3 shade_diffuse(vec3 n, vec3 albedo) {
    return albedo * (0.45 + 0.55 * max(dot(n, u_light_dir), 0.0));
}

void main() {
    vec3 to_eye = u_eye - v_world;
    vec3 v = normalize(to_eye);
    float len = length(v_normal);
    vec3 n = len > 1e-6 ? v_normal / len : v;
    // Culling is off, so back faces arrive too: light the side that faces the viewer.
    if (dot(n, v) < 0.0) n = -n;
    vec3 color;
    if (u_material == 0) {
        color = shade_water(n, v);
    } else if (u_material == 1) {
        color = shade_diffuse(n, vec3(0.60, 0.60, 0.62));
    } else {
        vec2 cell = floor(v_world.xz * 2.0);
        bool odd = mod(cell.x + cell.y, 2.0) > 0.5;
        color = shade_diffuse(n, odd ? vec3(0.80, 0.76, 0.67) : vec3(0.70, 0.67, 0.60));
        // Fade into the horizon colour so the plane's far edge and checker aliasing disappear.
        color = mix(color, kHorizon, smoothstep(15.0, 55.0, length(to_eye)));
    }
    frag_color = vec4(color, 1.0);
}
)";

const char* const kSkyVertex = R"(#version 450 core
out vec2 v_ndc;
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    v_ndc = p;
    gl_Position = vec4(p, 1.0, 1.0);
}
)";

const char* const kSkyFragment = R"(
uniform vec3 u_forward;
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec2 u_half_extent;
in vec2 v_ndc;
out vec4 frag_color;
void main() {
    vec3 dir = normalize(u_forward + v_ndc.x * u_half_extent.x * u_right + v_ndc.y * u_half_extent.y * u_up);
    frag_color = vec4(sky_color(dir), 1.0);
}
)";

}  // namespace rivulet::shaders
