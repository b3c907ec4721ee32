#include "systems/render/screen_fluid_shaders.h"

namespace rivulet::shaders {

const char* const kVersion = "#version 450 core\n";

// Camera uniforms every screen-fluid stage shares: the basis of camera_basis() and the half extents of
// the image plane at distance 1 (tan of the half field of view, times the aspect for x).
const char* const kScreenCamera = R"(
uniform vec3 u_eye;
uniform vec3 u_forward;
uniform vec3 u_right;
uniform vec3 u_up;
uniform vec2 u_half_extent;
uniform mat4 u_view_proj;
uniform vec2 u_viewport;  // pixels of the target being drawn
// The ray through a point of the target, as a direction whose forward component is 1: a point at
// eye-space depth d along it is u_eye + d * ray.
vec3 pixel_ray(vec2 frag) {
    vec2 ndc = frag / u_viewport * 2.0 - 1.0;
    return u_forward + ndc.x * u_half_extent.x * u_right + ndc.y * u_half_extent.y * u_up;
}
)";

// One camera-facing quad per particle, just large enough to cover the sphere's outline: in the plane
// through the centre across the line of sight, the tangent cone from the eye meets it at
// r d / sqrt(d^2 - r^2).
const char* const kSphereQuadVertex = R"(
layout(location = 0) in float a_x;
layout(location = 1) in float a_y;
layout(location = 2) in float a_z;
uniform float u_radius;
flat out vec3 v_center;
void main() {
    v_center = vec3(a_x, a_y, a_z);
    vec3 to_center = v_center - u_eye;
    float d = length(to_center);
    vec3 view = d > 0.0 ? to_center / d : u_forward;
    vec3 side = normalize(abs(view.y) < 0.99 ? cross(view, vec3(0.0, 1.0, 0.0)) : cross(view, vec3(1.0, 0.0, 0.0)));
    vec3 up = cross(side, view);
    float reach = d > u_radius * 1.001 ? u_radius * d / sqrt(d * d - u_radius * u_radius) : 0.0;
    vec2 corner = vec2(gl_VertexID & 1, gl_VertexID >> 1) * 2.0 - 1.0;
    vec3 p = v_center + reach * (corner.x * side + corner.y * up);
    gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

// Where the pixel's ray meets the particle's sphere: the eye-space depth of the nearer hit (the
// sphere's true depth, not the quad's) and the chord's length, or a discard.
const char* const kSphereHit = R"(
uniform float u_radius;
flat in vec3 v_center;
bool sphere_hit(out float depth, out float chord) {
    vec3 ray = pixel_ray(gl_FragCoord.xy);
    vec3 oc = u_eye - v_center;
    float a = dot(ray, ray), b = dot(oc, ray), c = dot(oc, oc) - u_radius * u_radius;
    float disc = b * b - a * c;
    if (disc <= 0.0) return false;
    float root = sqrt(disc);
    depth = (-b - root) / a;
    chord = 2.0 * root / a * length(ray);
    return depth > 0.0;
}
)";

// Depth pass: linear eye-space depth into a float target, and the matching window depth so the nearest
// sphere wins the depth test.
const char* const kSphereDepthFragment = R"(
out float frag_depth;
void main() {
    float depth, chord;
    if (!sphere_hit(depth, chord)) discard;
    vec4 clip = u_view_proj * vec4(u_eye + depth * pixel_ray(gl_FragCoord.xy), 1.0);
    gl_FragDepth = clip.z / clip.w * 0.5 + 0.5;
    frag_depth = depth;
}
)";

// Thickness pass: every sphere's chord along the ray, summed by additive blending.
const char* const kSphereThicknessFragment = R"(
out float frag_thickness;
void main() {
    float depth, chord;
    if (!sphere_hit(depth, chord)) discard;
    frag_thickness = chord;
}
)";

// At the far plane (window depth 1): with the depth pass's buffer attached and GL_GREATER, only pixels a
// sphere covered are shaded.
const char* const kFullScreenVertex = R"(#version 450 core
void main() {
    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
    gl_Position = vec4(p, 1.0, 1.0);
}
)";

// One direction of the separable bilateral filter (the seed's §3.1.2.1 approximation): a Gaussian over
// pixels whose screen radius follows depth (a fixed world-space width), times a Gaussian over depth
// differences so separate sheets do not blend. Background pixels (depth 0) are neither changed nor used,
// so silhouettes do not bleed into the background.
const char* const kBilateralFragment = R"(
uniform sampler2D u_depth;
uniform ivec2 u_step;          // (1, 0) or (0, 1)
uniform float u_world_sigma;   // world units
uniform float u_depth_sigma;   // world units
uniform int u_max_radius;      // pixels
out float frag_depth;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(u_depth, p, 0).r;
    if (d <= 0.0) { frag_depth = 0.0; return; }
    // Pixels per world unit at depth d.
    float scale = 0.5 * u_viewport.y / (u_half_extent.y * d);
    float sigma = max(u_world_sigma * scale, 0.5);
    int radius = min(int(ceil(2.0 * sigma)), u_max_radius);
    ivec2 size = textureSize(u_depth, 0);
    float sum = 0.0, weight = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        ivec2 q = clamp(p + i * u_step, ivec2(0), size - 1);
        float s = texelFetch(u_depth, q, 0).r;
        if (s <= 0.0) continue;
        float ds = (s - d) / u_depth_sigma;
        float w = exp(-0.5 * float(i * i) / (sigma * sigma) - 0.5 * ds * ds);
        sum += w * s;
        weight += w;
    }
    frag_depth = sum / weight;
}
)";

// The water: normals from the smoothed depth (the smaller one-sided difference at depth edges), a Schlick
// Fresnel mix of the sky's reflection and the refracted scene behind (offset along the normal by the
// thickness), Beer-Lambert absorption by thickness, a specular highlight. Where there is no fluid, or the
// scene is nearer, the scene is copied through unchanged.
const char* const kCompositeFragment = R"(
uniform sampler2D u_depth;       // smoothed eye-space depth, 0 = no fluid
uniform sampler2D u_thickness;   // reduced resolution
uniform sampler2D u_scene_color;
uniform sampler2D u_scene_depth; // window depth of the scene behind
uniform vec3 u_light_dir;
uniform vec3 u_absorption;       // per metre of water, per channel
uniform vec3 u_water_color;
uniform float u_refraction;
uniform vec2 u_near_far;
out vec4 frag_color;

float scene_eye_depth(ivec2 p) {
    float z = texelFetch(u_scene_depth, p, 0).r * 2.0 - 1.0;
    float n = u_near_far.x, f = u_near_far.y;
    return 2.0 * n * f / (f + n - z * (f - n));  // along the view axis
}

vec3 eye_point(ivec2 p, float d) {
    return u_eye + d * pixel_ray(vec2(p) + 0.5);
}

// The neighbour difference of smaller depth change: across a silhouette the far side is another surface.
vec3 side_difference(ivec2 p, ivec2 step, float d, vec3 here) {
    ivec2 size = textureSize(u_depth, 0);
    ivec2 a = clamp(p + step, ivec2(0), size - 1), b = clamp(p - step, ivec2(0), size - 1);
    float da = texelFetch(u_depth, a, 0).r, db = texelFetch(u_depth, b, 0).r;
    bool use_a = da > 0.0 && (db <= 0.0 || abs(da - d) <= abs(db - d));
    if (use_a) return eye_point(a, da) - here;
    if (db > 0.0) return here - eye_point(b, db);
    return vec3(0.0);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec3 scene = texelFetch(u_scene_color, p, 0).rgb;
    float d = texelFetch(u_depth, p, 0).r;
    if (d <= 0.0 || d >= scene_eye_depth(p)) { frag_color = vec4(scene, 1.0); return; }
    vec3 here = eye_point(p, d);
    vec3 dx = side_difference(p, ivec2(1, 0), d, here);
    vec3 dy = side_difference(p, ivec2(0, 1), d, here);
    vec3 v = normalize(u_eye - here);
    vec3 n = cross(dx, dy);
    n = dot(n, n) > 0.0 ? normalize(n) : v;
    if (dot(n, v) < 0.0) n = -n;
    float thickness = texture(u_thickness, (vec2(p) + 0.5) / u_viewport).r;

    float ndv = max(dot(n, v), 0.0);
    float fresnel = 0.02 + 0.98 * pow(1.0 - ndv, 5.0);
    vec3 reflected = sky_color(reflect(-v, n));
    vec2 offset = vec2(dot(n, u_right), dot(n, u_up)) * u_refraction * min(thickness, 0.2);
    vec2 uv = clamp((vec2(p) + 0.5) / u_viewport - offset, vec2(0.0), vec2(1.0));
    vec3 behind = texture(u_scene_color, uv).rgb;
    vec3 transmitted = mix(u_water_color, behind, exp(-u_absorption * thickness));
    float spec = pow(max(dot(n, normalize(u_light_dir + v)), 0.0), 96.0);
    frag_color = vec4(mix(transmitted, reflected, fresnel) + vec3(spec * (0.3 + 0.7 * fresnel)), 1.0);
}
)";

}  // namespace rivulet::shaders
