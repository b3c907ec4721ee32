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

// One camera-facing triangle per particle around the sphere's outline: in the plane through the centre
// across the line of sight, the tangent cone from the eye meets it in a circle of radius
// r d / sqrt(d^2 - r^2), and the equilateral triangle around that circle (a thousandth wider) covers
// the outline. A triangle, not a quad: for spheres a few pixels across llvmpipe's cost is mostly per
// triangle, not per fragment. On the dam break's 23k spheres the triangle's 30 % more fragments (those
// outside the outline discarded) made the depth pass 5 % and the thickness pass 17 % faster than a
// quad's two triangles, on the fountain's larger spheres neither faster nor slower; an octagon's six
// triangles made the dam break's depth pass 1.6x slower (perf/RESULTS.md).
const char* const kSphereTriangleVertex = R"(
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
    const vec2 corners[3] = vec2[3](vec2(0.0, 2.002), vec2(-1.7338, -1.001), vec2(1.7338, -1.001));
    vec2 corner = corners[gl_VertexID];
    vec3 p = v_center + reach * (corner.x * side + corner.y * up);
    gl_Position = u_view_proj * vec4(p, 1.0);
}
)";

// Where the pixel's ray meets the particle's sphere: the eye-space depth of the nearer hit (the
// sphere's true depth, not the triangle's) and the chord's length, or a discard.
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
// sphere wins the depth test. u_push moves every hit back along the view axis: spheres drawn larger than
// the particles (screen_depth_radius) are pushed back by the difference, so a flat surface stays one
// particle radius outside the centres.
const char* const kSphereDepthFragment = R"(
uniform float u_push;     // world units
uniform vec2 u_window_z;  // the projection's window depth at view depth d is x - y / d
out float frag_depth;
void main() {
    float depth, chord;
    if (!sphere_hit(depth, chord)) discard;
    depth += u_push;
    gl_FragDepth = u_window_z.x - u_window_z.y / depth;
    frag_depth = depth;
}
)";

// Thickness pass: every sphere's chord along the ray, summed by additive blending (target 0), and the
// span from the nearest sphere's entry to the farthest one's exit by GL_MAX (target 1). Overlapping
// spheres (a fountain's stream is denser than its radius) sum their common water many times over; the
// resolve (shaders.h kThicknessResolveFragment, as for the meshes) keeps the sum within the span, so the
// three methods absorb alike.
const char* const kSphereThicknessFragment = R"(
layout(location = 0) out float frag_thickness;
layout(location = 1) out vec2 frag_span;
void main() {
    float depth, chord;
    if (!sphere_hit(depth, chord)) discard;
    frag_thickness = chord;
    float near = depth * length(pixel_ray(gl_FragCoord.xy));  // along the ray, as the chord
    frag_span = vec2(near + chord, -near);
}
)";

// The width every smoothing filter shares: a Gaussian whose sigma is a fixed world length, so its screen
// radius follows depth (far fluid is not smoothed more than near fluid), at most u_max_radius pixels,
// read with at most u_max_taps taps a side (a stride beyond that), and the depth sampler both read.
const char* const kFilterWidth = R"(
uniform sampler2D u_depth;
uniform ivec2 u_step;          // (1, 0) or (0, 1)
uniform float u_world_sigma;   // world units
uniform int u_max_radius;      // pixels
uniform int u_max_taps;        // per side
struct FilterWidth { float sigma; int taps; int stride; };
FilterWidth filter_width(float d) {
    float scale = 0.5 * u_viewport.y / (u_half_extent.y * d);  // pixels per world unit at depth d
    float sigma = max(u_world_sigma * scale, 0.5);
    int radius = min(int(ceil(2.0 * sigma)), u_max_radius);
    int stride = max(1, (radius + u_max_taps - 1) / u_max_taps);
    return FilterWidth(sigma, radius / stride, stride);
}
// The Gaussian's weights at taps 1, 2, ... by recurrence (one exp a pixel, not one a tap): with
// a = exp(-stride^2 / (2 sigma^2)) tap t weighs a^(t^2), and a^((t+1)^2) = a^(t^2) a^(2t+1).
struct TapWeights { float w; float ratio; float a2; };
TapWeights first_tap(FilterWidth f) {
    float a = exp(-0.5 * float(f.stride * f.stride) / (f.sigma * f.sigma));
    return TapWeights(a, a * a * a, a * a);
}
void next_tap(inout TapWeights g) {
    g.w *= g.ratio;
    g.ratio *= g.a2;
}
// The depth i pixels along u_step from p, clamped to the target.
float depth_along(ivec2 p, int i) {
    return texelFetch(u_depth, clamp(p + i * u_step, ivec2(0), textureSize(u_depth, 0) - 1), 0).r;
}
)";

// Closes pinholes and pits of the sphere depth: where particles sit about a diameter apart, rays slip
// between them and show the floor, or a particle a layer deeper, through single pixels; a per-pixel
// filter keeps such a pixel as a separate surface. A pixel with nearer fluid on both sides along x or
// along y, within u_reach pixels, the two sides within u_jump of each other and both more than u_gap
// nearer than the pixel (background counts as infinitely far), takes their mean. A slope has one side
// nearer and one farther and an outline has fluid on one side only, so neither changes. Writes the
// depth-test buffer too, so the smoothing passes see filled pixels.
const char* const kCloseHolesFragment = R"(
uniform sampler2D u_depth;
uniform int u_reach;    // pixels
uniform float u_jump;   // world units
uniform float u_gap;    // world units
out float frag_depth;
float nearest_surface(ivec2 p, ivec2 step) {
    ivec2 size = textureSize(u_depth, 0);
    float m = 0.0;
    for (int i = 1; i <= u_reach; ++i) {
        float s = texelFetch(u_depth, clamp(p + i * step, ivec2(0), size - 1), 0).r;
        if (s > 0.0 && (m == 0.0 || s < m)) m = s;
    }
    return m;
}
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(u_depth, p, 0).r;
    float limit = (d > 0.0 ? d : 3.0e38) - u_gap;
    float sum = 0.0, count = 0.0;
    float l = nearest_surface(p, ivec2(-1, 0)), r = nearest_surface(p, ivec2(1, 0));
    if (l > 0.0 && r > 0.0 && abs(l - r) < u_jump && max(l, r) < limit) sum += l + r, count += 2.0;
    float b = nearest_surface(p, ivec2(0, -1)), t = nearest_surface(p, ivec2(0, 1));
    if (b > 0.0 && t > 0.0 && abs(b - t) < u_jump && max(b, t) < limit) sum += b + t, count += 2.0;
    if (count > 0.0) d = sum / count;
    if (d <= 0.0) discard;
    frag_depth = d;
    gl_FragDepth = 0.5;  // anything nearer than the far plane marks the pixel as fluid
}
)";

// One direction of the separable bilateral filter (the approximation of Janisz §3.1.2.1): the shared
// Gaussian over pixels, times a Gaussian over depth differences so separate sheets do not blend.
// Background pixels (depth 0) are neither changed nor used, so silhouettes do not bleed into the
// background.
const char* const kBilateralFragment = R"(
uniform float u_depth_sigma;   // world units
out float frag_depth;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(u_depth, p, 0).r;
    if (d <= 0.0) { frag_depth = 0.0; return; }
    FilterWidth f = filter_width(d);
    float sum = d, weight = 1.0;
    TapWeights g = first_tap(f);
    for (int t = 1; t <= f.taps; ++t) {
        int i = t * f.stride;
        float a = depth_along(p, i), b = depth_along(p, -i);
        float da = (a - d) / u_depth_sigma, db = (b - d) / u_depth_sigma;
        float wa = a > 0.0 ? g.w * exp(-0.5 * da * da) : 0.0;
        float wb = b > 0.0 ? g.w * exp(-0.5 * db * db) : 0.0;
        sum += wa * a + wb * b;
        weight += wa + wb;
        next_tap(g);
    }
    frag_depth = sum / weight;
}
)";

// One direction of the narrow-range filter (Truong & Yuksel 2018). Samples are taken in symmetric
// pairs with plain Gaussian weights, but only inside a depth range around the pixel that starts at
// +-u_threshold and widens as accepted samples extend it, so a slope is followed while a separate sheet
// is not: a pair with a sample in front of the range is skipped whole (the kernel stays symmetric and
// the nearer sheet leaves no halo), and a sample behind it counts as the pixel's depth + u_clamp. The
// background counts as behind everything, which rounds silhouettes off without moving them.
const char* const kNarrowRangeFragment = R"(
uniform float u_threshold;   // world units
uniform float u_clamp;       // world units
out float frag_depth;
float far_if_empty(float s) { return s > 0.0 ? s : 3.0e38; }
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float d = texelFetch(u_depth, p, 0).r;
    if (d <= 0.0) { frag_depth = 0.0; return; }
    FilterWidth f = filter_width(d);
    float low = d - u_threshold, high = d + u_threshold, behind = d + u_clamp;
    float sum = d, weight = 1.0;
    TapWeights g = first_tap(f);
    for (int t = 1; t <= f.taps; ++t) {
        int i = t * f.stride;
        float a = far_if_empty(depth_along(p, i));
        float b = far_if_empty(depth_along(p, -i));
        if (a >= low && b >= low) {
            a = a > high ? behind : a;
            b = b > high ? behind : b;
            low = min(low, min(a, b) - u_threshold);
            high = max(high, max(a, b) + u_threshold);
            sum += g.w * (a + b);
            weight += 2.0 * g.w;
        }
        next_tap(g);
    }
    frag_depth = sum / weight;
}
)";

// One explicit step of screen-space curvature flow (van der Laan, Green & Sainz 2009, Janisz
// §3.1.2.2): the depth moves against the surface's mean curvature H computed from its screen-space
// derivatives. Where a neighbour is background or lies beyond a depth jump, the surface is taken to
// continue flat (a zero one-sided difference), so silhouettes stay put. The step is chosen per pixel:
// small enough for stability (a diffusion number of at most 0.2 per pixel) and, where the pixels allow,
// the step that spreads over the world-space sigma in u_iterations steps.
const char* const kCurvatureFlowFragment = R"(
uniform sampler2D u_depth;
uniform float u_world_sigma;  // world units
uniform float u_jump;         // world units: a larger depth difference is another surface
uniform float u_max_step;     // world units: no pixel moves further in one step
uniform int u_iterations;
out float frag_depth;
float neighbour(ivec2 q, float d) {
    ivec2 size = textureSize(u_depth, 0);
    float s = texelFetch(u_depth, clamp(q, ivec2(0), size - 1), 0).r;
    return (s > 0.0 && abs(s - d) < u_jump) ? s : d;
}
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float z = texelFetch(u_depth, p, 0).r;
    if (z <= 0.0) { frag_depth = 0.0; return; }
    float l = neighbour(p + ivec2(-1, 0), z), r = neighbour(p + ivec2(1, 0), z);
    float b = neighbour(p + ivec2(0, -1), z), t = neighbour(p + ivec2(0, 1), z);
    float bl = neighbour(p + ivec2(-1, -1), z), br = neighbour(p + ivec2(1, -1), z);
    float tl = neighbour(p + ivec2(-1, 1), z), tr = neighbour(p + ivec2(1, 1), z);
    float zx = 0.5 * (r - l), zy = 0.5 * (t - b);
    float zxx = r + l - 2.0 * z, zyy = t + b - 2.0 * z, zxy = 0.25 * (tr - tl - br + bl);
    // World size of a pixel per unit depth, along x and y.
    float cx = 2.0 * u_half_extent.x / u_viewport.x, cy = 2.0 * u_half_extent.y / u_viewport.y;
    float cx2 = cx * cx, cy2 = cy * cy;
    float D = cy2 * zx * zx + cx2 * zy * zy + cx2 * cy2 * z * z;
    float dDx = 2.0 * (cy2 * zx * zxx + cx2 * zy * zxy + cx2 * cy2 * z * zx);
    float dDy = 2.0 * (cy2 * zx * zxy + cx2 * zy * zyy + cx2 * cy2 * z * zy);
    float ex = 0.5 * zx * dDx - zxx * D, ey = 0.5 * zy * dDy - zyy * D;
    float h = (cy * ex + cx * ey) / (2.0 * D * sqrt(D));
    // For a gently sloped sheet -h ~ (zxx + zyy) / (2 pixel): a step of 2 pixel k diffuses by k per
    // pixel^2; k spreads sigma_pixels^2 / (2 iterations) over the run.
    float pixel = cx * z;
    float spread = u_world_sigma / pixel;
    float k = min(0.2, spread * spread / (2.0 * float(u_iterations)));
    frag_depth = z + clamp(-2.0 * pixel * k * h, -u_max_step, u_max_step);
}
)";

// One direction of a plain Gaussian over the reduced-resolution thickness (Janisz §3.1.3).
const char* const kThicknessBlurFragment = R"(
uniform sampler2D u_thickness;
uniform ivec2 u_step;
uniform float u_sigma;  // pixels of the thickness target
out float frag_thickness;
void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    ivec2 size = textureSize(u_thickness, 0);
    int radius = int(ceil(2.0 * u_sigma));
    float sum = 0.0, weight = 0.0;
    for (int i = -radius; i <= radius; ++i) {
        float w = exp(-0.5 * float(i * i) / (u_sigma * u_sigma));
        sum += w * texelFetch(u_thickness, clamp(p + i * u_step, ivec2(0), size - 1), 0).r;
        weight += w;
    }
    frag_thickness = sum / weight;
}
)";

// The water: normals from the smoothed depth (the smaller one-sided difference at depth edges), a Schlick
// Fresnel mix of the sky's reflection and the refracted scene behind (offset along the normal by the
// thickness), Beer-Lambert absorption by thickness, a specular highlight. Where there is no fluid, or the
// scene is nearer, the scene is copied through unchanged.
const char* const kCompositeFragment = R"(
uniform sampler2D u_depth;       // smoothed eye-space depth, 0 = no fluid
uniform sampler2D u_thickness;   // reduced resolution
uniform vec3 u_light_dir;
uniform samplerCube u_environment;
uniform bool u_has_environment;  // else the analytic sky
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
    vec3 v = normalize(u_eye - here);
    vec3 n = cross(side_difference(p, ivec2(1, 0), d, here), side_difference(p, ivec2(0, 1), d, here));
    n = dot(n, n) > 0.0 ? normalize(n) : v;
    if (dot(n, v) < 0.0) n = -n;
    vec2 uv = (vec2(p) + 0.5) / u_viewport;
    float thickness = texture(u_thickness, uv).r;
    vec3 r = reflect(-v, n);
    vec3 reflected = u_has_environment ? texture(u_environment, r).rgb : sky_color(r);
    float highlight = pow(max(dot(n, normalize(u_light_dir + v)), 0.0), 96.0);
    vec3 color = shade_water(n, v, reflected, thickness, uv, vec2(dot(n, u_right), dot(n, u_up)), highlight,
                             water_window_depth(d, u_near_far));
    frag_color = vec4(color, 1.0);
}
)";

// Spray (Green, GDC 2010): a round point sprite a little smaller than the particle's projected size.
// Sprites that would cover less than a pixel keep their size and fade by the area they would have had,
// so far spray stays fine and dim instead of turning into single-pixel noise.
const char* const kSprayVertex = R"(
layout(location = 0) in float a_x;
layout(location = 1) in float a_y;
layout(location = 2) in float a_z;
uniform float u_radius;
uniform float u_size;  // sprite diameter in particle diameters
flat out float v_depth;
flat out float v_fade;
void main() {
    vec3 p = vec3(a_x, a_y, a_z);
    v_depth = dot(p - u_eye, u_forward);
    gl_Position = u_view_proj * vec4(p, 1.0);
    float pixels = v_depth > 0.0 ? u_size * u_radius * u_viewport.y / (u_half_extent.y * v_depth) : 0.0;
    gl_PointSize = max(pixels, 1.0);
    v_fade = min(pixels * pixels, 1.0);
}
)";

// Bright water-tinted white with a soft round edge; hidden where the water's surface is in front (the
// solids in front are the depth test's).
const char* const kSprayFragment = R"(
uniform sampler2D u_depth;  // the water's smoothed eye-space depth, 0 = no water
uniform vec3 u_water_color;
uniform float u_radius;
flat in float v_depth;
flat in float v_fade;
out vec4 frag_color;
void main() {
    vec2 q = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(q, q);
    if (r2 > 1.0) discard;
    float water = texelFetch(u_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (water > 0.0 && v_depth > water + u_radius) discard;
    float alpha = (1.0 - r2) * (1.0 - r2) * v_fade;
    frag_color = vec4(mix(vec3(1.0), u_water_color, 0.12), alpha);
}
)";

}  // namespace rivulet::shaders
