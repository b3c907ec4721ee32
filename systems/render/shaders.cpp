#include "systems/render/shaders.h"

namespace rivulet::shaders {

// A pale, barely blue sky: water has to stand out from the background in pictures and in the tests
// that tell them apart by colour. sky_radiance() (environment_map.cpp) is the same sky plus a glow
// towards the light; keep the two in step.
const char* const kFragmentPrelude = R"(#version 450 core
const vec3 kHorizon = vec3(0.86, 0.88, 0.90);
const vec3 kZenith = vec3(0.70, 0.77, 0.85);
const vec3 kGroundBounce = vec3(0.55, 0.52, 0.47);
vec3 sky_color(vec3 dir) {
    if (dir.y < 0.0) return mix(kHorizon, kGroundBounce, clamp(-dir.y * 3.0, 0.0, 1.0));
    return mix(kHorizon, kZenith, sqrt(dir.y));
}
)";

// gl_ClipDistance 0-3 keep what lies inside u_clip (x0, z0, x1, z1) when the renderer enables them.
const char* const kLitVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_offset;
uniform mat4 u_view_proj;
uniform float u_scale;
uniform vec4 u_clip;
out vec3 v_world;
out vec3 v_normal;
out float gl_ClipDistance[4];
void main() {
    v_world = a_position * u_scale + a_offset;
    v_normal = a_normal;
    gl_Position = u_view_proj * vec4(v_world, 1.0);
    gl_ClipDistance[0] = v_world.x - u_clip.x;
    gl_ClipDistance[1] = v_world.z - u_clip.y;
    gl_ClipDistance[2] = u_clip.z - v_world.x;
    gl_ClipDistance[3] = u_clip.w - v_world.z;
}
)";

const char* const kLitFragment = R"(
uniform vec3 u_eye;
uniform vec3 u_light_dir;
uniform vec3 u_right;     // water: the camera's axes, to turn the normal into a screen offset
uniform vec3 u_up;
uniform vec2 u_viewport;  // water: the picture's pixels
uniform sampler2D u_thickness;  // water: the fluid's thickness per pixel (reduced resolution)
// The pool: a height field has no back, so it absorbs over the depth of water under it.
uniform float u_slab_depth;
uniform vec3 u_horizon;  // ground: the environment's mean horizon colour
uniform vec3 u_albedo;   // solids
uniform float u_shine;  // solids: strength of a broad highlight
uniform samplerCube u_environment;
// Reflections read one fixed level of about kSkyFaceSize² a face: a curved surface would need a level
// per pixel, which costs llvmpipe as much as the rest of the water's shading, and the sharper levels of
// a large loaded map would only sparkle on ripples.
uniform float u_reflection_lod;
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_shadow_matrix;
uniform float u_shadow_texel;
in vec3 v_world;
in vec3 v_normal;
out vec4 frag_color;

// How much of the key light reaches this point: 1 lit, 0 in shadow. `n` faces the viewer.
float light_reaching(vec3 n, float ndl) {
    // Normal offset: the lookup sits a texel or so off the surface, more where the light grazes it, so a
    // surface never shadows itself (acne) and contact shadows do not detach (peter-panning).
    vec3 p = v_world + n * (u_shadow_texel * (1.0 + 2.0 * (1.0 - ndl)));
    vec3 c = (u_shadow_matrix * vec4(p, 1.0)).xyz;
    c.z = min(c.z, 1.0);
    // Two bilinear comparisons (2, 1) texels apart: an edge two to three texels soft (a pixel or two at
    // the scenes' framing). Each tap costs llvmpipe about as much as the rest of the shading, so two,
    // not the usual four or more. An odd step also makes water's every-other-texel shadow (kShadowFragment)
    // average to exactly one half. Outside the map the border compares as lit.
    vec2 t = vec2(1.0, 0.5) / float(textureSize(u_shadow_map, 0).x);
    float s = textureLod(u_shadow_map, vec3(c.xy - t, c.z), 0.0) + textureLod(u_shadow_map, vec3(c.xy + t, c.z), 0.0);
    return ndl > 0.0 ? 0.5 * s : 0.0;
}

float specular(vec3 n, vec3 v, float power) {
    return pow(max(dot(n, normalize(u_light_dir + v)), 0.0), power);
}

vec3 shade_diffuse(vec3 albedo, float direct) {
    return albedo * (0.45 + 0.55 * direct);
}

void main() {
    vec3 to_eye = u_eye - v_world;
    vec3 v = normalize(to_eye);
    float len = length(v_normal);
    vec3 n = len > 1e-6 ? v_normal / len : v;
    // Culling is off, so back faces arrive too: light the side that faces the viewer.
    if (dot(n, v) < 0.0) n = -n;
#if LIT_VARIANT == 3
    // Glass: mostly clear with a faint green-blue body, turning into a mirror of the environment towards
    // grazing angles; that rim is what shows a glass wall's edges. Unshadowed: it is barely there.
    float fresnel = 0.04 + 0.96 * pow(1.0 - max(dot(n, v), 0.0), 5.0);
    vec3 reflected = textureLod(u_environment, reflect(-v, n), u_reflection_lod).rgb;
    float spec = specular(n, v, 240.0);
    vec3 color = mix(vec3(0.80, 0.92, 0.93), reflected, fresnel) + vec3(spec);
    frag_color = vec4(color, clamp(0.08 + 0.8 * fresnel + spec, 0.0, 0.9));
#else
    float ndl = max(dot(n, u_light_dir), 0.0);
#if LIT_VARIANT == 4
    float direct = ndl;  // beyond the shadow map's reach
#elif LIT_VARIANT == 0 || LIT_VARIANT == 5
    // Water takes no shadow lookups: its body colour is the light through it, which the screen-space
    // composite cannot shadow either, and two taps cost llvmpipe as much as the rest of its shading.
    float direct = ndl;
#else
    float direct = ndl * light_reaching(n, ndl);
#endif
#if LIT_VARIANT == 0 || LIT_VARIANT == 5
    // Water: the composite the screen-space method uses, with the thickness of the closed surface
    // (kMeshThicknessFragment) or, for the pool, of the slab under it along the view ray.
    vec2 uv = gl_FragCoord.xy / u_viewport;
#if LIT_VARIANT == 5
    float thickness = u_slab_depth / max(v.y, 0.15);
    // No refraction mask over the pool: at grazing angles its slab's offset is long, and the floor a long
    // offset nearer the eye lies in front of this pixel's surface though it is under the water, so the
    // mask would cut the refracted floor into jagged bands.
    float front_z = 0.0;
#else
    float thickness = max(texture(u_thickness, uv).r, 0.0);
    float front_z = gl_FragCoord.z;
#endif
    vec3 reflected = textureLod(u_environment, reflect(-v, n), u_reflection_lod).rgb;
    float highlight = step(1e-4, direct) * specular(n, v, 96.0);
    vec3 color = shade_water(n, v, reflected, thickness, uv, vec2(dot(n, u_right), dot(n, u_up)), highlight,
                             front_z);
#elif LIT_VARIANT == 2 || LIT_VARIANT == 4
    // Ground: a checker, faded into the environment's horizon so the plane's far edge and the checker's
    // aliasing disappear.
    vec2 cell = floor(v_world.xz * 2.0);
    bool odd = mod(cell.x + cell.y, 2.0) > 0.5;
    vec3 color = shade_diffuse(odd ? vec3(0.80, 0.76, 0.67) : vec3(0.70, 0.67, 0.60), direct);
    color = mix(color, u_horizon, smoothstep(15.0, 55.0, length(to_eye)));
#else
    // Solids: colliders, the pool rim, the tank's frame.
    vec3 color = shade_diffuse(u_albedo, direct) + vec3(u_shine * direct * specular(n, v, 32.0));
#endif
    frag_color = vec4(color, 1.0);
#endif
}
)";

// One water for every surface method (Janisz §3.1.4): a Schlick Fresnel mix of the reflected
// environment and the transmitted scene behind, which is offset along the normal by the thickness
// (refraction) and tinted towards the water's colour by Beer-Lambert absorption over it, plus the key
// light's highlight. The screen-space composite and the lit meshes' water both call shade_water, so
// three methods of one frame differ only in their surface.
//
// The scene copy holds what stands in front of the water too (the tank's front posts and bars), and an
// offset lookup that lands on it would show it through the water: dark blotches over a whole surge wall
// where the frame's posts lie a refraction offset away. Where the scene at the offset lies nearer than
// the water's own front, the unshifted scene is taken instead (the usual refraction mask).
const char* const kWaterShading = R"(
uniform vec3 u_water_color;   // what thick water tends to
uniform vec3 u_absorption;    // Beer-Lambert coefficients per metre, per channel
uniform float u_refraction;   // screen offset per unit of thickness and of the normal's screen part
uniform sampler2D u_scene_color;
uniform sampler2D u_scene_depth;  // window depth of the same scene
const float kWaterF0 = 0.02;  // reflectance of water at normal incidence ((1.33 - 1) / (1.33 + 1))^2
float water_fresnel(float cos_theta) {
    return kWaterF0 + (1.0 - kWaterF0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0);
}
// The window depth (what u_scene_depth holds) of a point d along the view axis, for a perspective
// projection with these near and far planes.
float water_window_depth(float d, vec2 near_far) {
    float n = near_far.x, f = near_far.y;
    return 0.5 + 0.5 * (f + n - 2.0 * n * f / d) / (f - n);
}
// n, v: the unit normal and the unit direction to the eye; reflected: the environment along the mirror
// direction; uv: this pixel in the scene colour; n_screen: the normal along the camera's right and up;
// highlight: the key light's specular term where the light reaches; front_z: the window depth of the
// water's surface at this pixel.
vec3 shade_water(vec3 n, vec3 v, vec3 reflected, float thickness, vec2 uv, vec2 n_screen, float highlight,
                 float front_z) {
    float fresnel = water_fresnel(dot(n, v));
    vec2 offset = n_screen * u_refraction * min(thickness, 0.2);
    vec2 shifted = clamp(uv - offset, vec2(0.0), vec2(1.0));
    vec4 z = textureGather(u_scene_depth, shifted);  // the four texels the colour's bilinear lookup blends
    if (min(min(z.x, z.y), min(z.z, z.w)) < front_z) shifted = uv;
    vec3 behind = texture(u_scene_color, shifted).rgb;
    vec3 transmitted = mix(u_water_color, behind, exp(-u_absorption * thickness));
    return mix(transmitted, reflected, fresnel) + vec3(highlight * (0.3 + 0.7 * fresnel));
}
)";

// Drawn with kLitVertex into two float targets with no depth test. Target 0 is blended additively: each
// fragment adds its distance from the eye where the ray leaves the water and subtracts it where it enters, so
// a closed surface sums to the length of water along the pixel's ray, however many times the ray crosses it.
// Which way a face points comes from its own plane (screen derivatives), turned outwards by the interpolated
// normal, so the meshes' winding does not matter. Target 1 is blended by GL_MAX into the farthest depth and
// the negated nearest: where a surface folds over itself or overlapping closed surfaces count their common
// water twice, the sum falls outside [0, far - near], and the resolve (kThicknessResolveFragment) falls back
// to that span.
const char* const kMeshThicknessFragment = R"(#version 450 core
uniform vec3 u_eye;
in vec3 v_world;
in vec3 v_normal;
layout(location = 0) out float signed_sum;
layout(location = 1) out vec2 span;
void main() {
    vec3 face = cross(dFdx(v_world), dFdy(v_world));
    float outward = dot(face, v_normal) >= 0.0 ? 1.0 : -1.0;
    bool entering = dot(face, u_eye - v_world) * outward > 0.0;
    float depth = length(v_world - u_eye);  // along the ray, so the sum is the path through the water
    signed_sum = entering ? -depth : depth;
    span = vec2(depth, -depth);
}
)";

// The isolated spheres' thickness as one round point each, not 42 vertices: a dam break drawn by scan
// conversion has some twenty thousand of them. Same targets and meaning as kMeshThicknessFragment: the
// chord into the sum, the exit and the negated entry into the span, distances along the ray.
const char* const kSphereThicknessPointVertex = R"(#version 450 core
layout(location = 0) in float a_x;
layout(location = 1) in float a_y;
layout(location = 2) in float a_z;
uniform mat4 u_view_proj;
uniform vec3 u_eye;
uniform float u_radius;
uniform float u_pixels_per_unit;  // of the target, at distance 1
uniform float u_max_point_size;
flat out vec3 v_center;
void main() {
    v_center = vec3(a_x, a_y, a_z);
    gl_Position = u_view_proj * vec4(v_center, 1.0);
    float d = max(length(v_center - u_eye) - u_radius, 1e-3);
    gl_PointSize = clamp(2.0 * u_radius * u_pixels_per_unit / d + 2.0, 1.0, u_max_point_size);
}
)";

const char* const kSphereThicknessPointFragment = R"(#version 450 core
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec2 u_half_extent;  // tan of the half field of view, times the aspect for x
uniform vec2 u_viewport;     // the thickness target's pixels
uniform float u_radius;
flat in vec3 v_center;
layout(location = 0) out float signed_sum;
layout(location = 1) out vec2 span;
void main() {
    vec2 ndc = gl_FragCoord.xy / u_viewport * 2.0 - 1.0;
    vec3 ray = normalize(u_forward + ndc.x * u_half_extent.x * u_right + ndc.y * u_half_extent.y * u_up);
    vec3 oc = u_eye - v_center;
    float b = dot(oc, ray), c = dot(oc, oc) - u_radius * u_radius;
    float disc = b * b - c;
    if (disc <= 0.0) discard;
    float root = sqrt(disc);
    float near = -b - root;
    if (near <= 0.0) discard;
    signed_sum = 2.0 * root;
    span = vec2(near + 2.0 * root, -near);
}
)";

// At the far plane (window depth 1): with the screen-space depth pass's buffer attached and GL_GREATER,
// only pixels a sphere covered are shaded; without a depth test it covers the target.
const char* const kFullScreenVertex = R"(#version 450 core
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 1.0, 1.0);
}
)";

const char* const kThicknessResolveFragment = R"(#version 450 core
uniform sampler2D u_signed_sum;
uniform sampler2D u_span;  // cleared to (0, -huge): x 0 where no fluid was drawn
out float thickness;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float sum = texelFetch(u_signed_sum, p, 0).r;
    vec2 span = texelFetch(u_span, p, 0).rg;
    float range = max(span.x + span.y, 0.0);
    thickness = span.x <= 0.0 ? 0.0 : (sum > 0.0 ? min(sum, range) : range);
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
uniform samplerCube u_environment;
in vec2 v_ndc;
out vec4 frag_color;
void main() {
    vec3 dir = normalize(u_forward + v_ndc.x * u_half_extent.x * u_right + v_ndc.y * u_half_extent.y * u_up);
    frag_color = vec4(texture(u_environment, dir).rgb, 1.0);
}
)";

const char* const kShadowVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 2) in vec3 a_offset;
uniform mat4 u_light_view_proj;
uniform float u_scale;
uniform vec4 u_clip;
out float gl_ClipDistance[4];
void main() {
    vec3 world = a_position * u_scale + a_offset;
    gl_Position = u_light_view_proj * vec4(world, 1.0);
    gl_ClipDistance[0] = world.x - u_clip.x;
    gl_ClipDistance[1] = world.z - u_clip.y;
    gl_ClipDistance[2] = u_clip.z - world.x;
    gl_ClipDistance[3] = u_clip.w - world.z;
}
)";

const char* const kShadowPointVertex = R"(#version 450 core
layout(location = 0) in float a_x;
layout(location = 1) in float a_y;
layout(location = 2) in float a_z;
uniform mat4 u_light_view_proj;
uniform float u_point_size;
void main() {
    gl_Position = u_light_view_proj * vec4(a_x, a_y, a_z, 1.0);
    gl_PointSize = u_point_size;
}
)";

// Water lets about half the light through: it casts its shadow into every other texel, which the lit
// shader's filtered lookups average into a half shadow (solids keep every texel).
const char* const kShadowFragment = R"(#version 450 core
uniform bool u_water;
void main() {
    if (u_water && ((int(gl_FragCoord.x) + int(gl_FragCoord.y)) & 1) == 1) discard;
}
)";

const char* const kShadowPointFragment = R"(#version 450 core
uniform float u_depth_radius;
void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0 || ((int(gl_FragCoord.x) + int(gl_FragCoord.y)) & 1) == 1) discard;  // water: a half shadow
    // The sphere's surface towards the light, not the flat disc through its centre; a little further
    // back stands in for the polygon offset that points do not get.
    gl_FragDepth = gl_FragCoord.z - (sqrt(1.0 - r2) - 0.1) * u_depth_radius;
}
)";

}  // namespace rivulet::shaders
