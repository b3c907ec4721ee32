#include "systems/render/volume_shaders.h"

#include <fmt/format.h>

#include "jobs/density_volume.h"

namespace rivulet::shaders {

std::string volume_layout_glsl() {
    return fmt::format(
        "const int kBrickCells = {};\nconst int kBrickEdge = {};\nconst int kAtlasBricks = {};\n"
        "const int kAtlasLayerBricks = {};\n",
        kBrickCells, kBrickEdge, kAtlasBricks, kAtlasLayerBricks);
}

// Krüger & Westermann (2003) start rays at the nearest face of the occupied blocks, rasterised. Here a
// block is 2^3 cells (volume_pass.cpp) and only the faces between a block some of whose samples reach
// the iso value and one none of whose do (or the grid's end) are drawn: a ray enters and leaves the
// region where the surface can be through those alone, and a pixel none of them covers is not raycast.
const char* const kVolumeShellVertex = R"(
layout(location = 0) in uint a_face;  // block index * 8 + face
uniform vec3 u_origin;  // world position of lattice point (0, 0, 0)
uniform float u_block;  // a block's edge, world units
uniform ivec3 u_blocks; // blocks per axis
out vec3 v_world;
// Corner c of a brick is (c & 1, (c >> 1) & 1, (c >> 2) & 1); each face's two triangles turn
// counter-clockwise seen from outside the brick, so gl_FrontFacing tells a ray's entry from its exit.
const int kFaceCorners[36] = int[36](0, 4, 6, 0, 6, 2,   1, 3, 7, 1, 7, 5,   0, 1, 5, 0, 5, 4,
                                     2, 6, 7, 2, 7, 3,   0, 2, 3, 0, 3, 1,   4, 5, 7, 4, 7, 6);
void main() {
    int b = int(a_face >> 3u), c = kFaceCorners[int(a_face & 7u) * 6 + gl_VertexID];
    ivec3 cell = ivec3(b % u_blocks.x, (b / u_blocks.x) % u_blocks.y, b / (u_blocks.x * u_blocks.y));
    // From integers, so neighbouring faces' shared corners are the same floats: no cracks between them.
    v_world = u_origin + vec3(cell + ivec3(c & 1, (c >> 1) & 1, (c >> 2) & 1)) * u_block;
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
)";

const char* const kVolumeShellFragment = R"(
in vec3 v_world;
out vec2 frag_span;
void main() {
    float t = dot(v_world - u_eye, u_forward);
    frag_span = gl_FrontFacing ? vec2(-t, 0.0) : vec2(-3.0e38, t);
}
)";

// Each pixel's ray, between the shell's nearest entry and farthest exit, walks the grid brick by brick (a
// 3D DDA; Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray Tracing", 1987) and marches only
// bricks that are stored and reach the iso value (Krüger & Westermann's empty-space skipping again: a
// trilinear field never exceeds the greatest of the samples it interpolates). Inside such a brick it steps
// u_step voxels until F crosses u_iso, bisects the crossing and takes the secant of the last bracket; the
// normal is the field's gradient. It stops at the scene's depth, so solids in front hide the water, and at
// the first hit (early ray termination). Behind the hit it keeps walking for the thickness the water
// absorbs over: whole bricks whose least sample reaches the iso value, coarser steps through the others,
// nothing through skipped ones, until the absorption saturates.
//
// t along the ray is eye-space depth (pixel_ray's forward component is 1); positions are in lattice
// units (voxels from the grid's origin).
const char* const kVolumeRaycastFragment = R"(
uniform sampler3D u_atlas;         // R32F: the stored bricks' samples
uniform sampler3D u_bricks;        // RGBA32F per brick: slot (-1: not stored), least, greatest sample
uniform samplerCube u_environment;
uniform bool u_has_environment;    // else the analytic sky
uniform float u_reflection_lod;
uniform vec3 u_light_dir;
uniform vec2 u_near_far;
uniform vec3 u_origin;             // world position of lattice point (0, 0, 0)
uniform float u_voxel;
uniform ivec3 u_grid;              // bricks per axis
uniform int u_max_bricks;          // the most bricks a ray can cross
uniform vec3 u_ray_lo;             // where rays look for water, lattice units: the grid, clipped
uniform vec3 u_ray_hi;
uniform vec3 u_atlas_scale;        // 1 / the atlas texture's size in texels
uniform float u_iso;
uniform float u_step;              // voxels
uniform int u_refine;
uniform float u_thickness_step;    // voxels
uniform float u_thickness_cap;     // world units
uniform bool u_use_span;           // the shell pass ran: rays walk its span only
uniform sampler2D u_span;          // its target (kVolumeShellFragment)
layout(location = 0) out vec4 frag_color;
layout(location = 1) out float frag_depth;
layout(location = 2) out float frag_thickness;

vec3 g_o, g_d;    // the ray: lattice point g_o + t g_d
vec3 g_lo;        // the current brick's first lattice point
vec3 g_texel;     // the texel centre of its first sample in the atlas

float scene_eye_depth(ivec2 p) {
    float z = texelFetch(u_scene_depth, p, 0).r * 2.0 - 1.0;
    float n = u_near_far.x, f = u_near_far.y;
    return 2.0 * n * f / (f + n - z * (f - n));
}

// The texel centre of a stored brick's first sample in the atlas.
vec3 slot_texel(float slot) {
    int s = int(slot);
    return vec3(ivec3(s % kAtlasBricks, (s / kAtlasBricks) % kAtlasBricks, s / kAtlasLayerBricks) * kBrickEdge) + 0.5;
}

void enter_brick(ivec3 cell, float slot) {
    g_lo = vec3(cell * kBrickCells);
    g_texel = slot_texel(slot);
}

// F at a point of the current brick, `local` lattice units from its first sample. A brick holds its
// far faces, so at texel centres the hardware's trilinear filter interpolates its own samples only;
// clamping into [0, 8] keeps the filter from ever weighting the next brick of the atlas.
float field_local(vec3 local) {
    vec3 u = clamp(local, 0.0, float(kBrickCells));
    return textureLod(u_atlas, (g_texel + u) * u_atlas_scale, 0.0).r;
}
float field(float t) {
    return field_local(g_o + t * g_d - g_lo);
}

// F at lattice point q anywhere in the grid: from the brick that holds it (either one on a shared
// face: both hold the same samples), 0 in bricks not stored.
float field_anywhere(vec3 q) {
    ivec3 cell = clamp(ivec3(floor(q / float(kBrickCells))), ivec3(0), u_grid - 1);
    float slot = texelFetch(u_bricks, cell, 0).x;
    if (slot < 0.0) return 0.0;
    vec3 u = clamp(q - vec3(cell * kBrickCells), 0.0, float(kBrickCells));
    return textureLod(u_atlas, (slot_texel(slot) + u) * u_atlas_scale, 0.0).r;
}

// Central differences half a voxel to either side, read from whichever brick holds each point: the
// trilinear field's slope jumps at every lattice plane, and a difference kept inside one brick would
// show those jumps as seams along the bricks' faces.
vec3 gradient(vec3 q) {
    vec3 ex = vec3(0.5, 0.0, 0.0), ey = vec3(0.0, 0.5, 0.0), ez = vec3(0.0, 0.0, 0.5);
    return vec3(field_anywhere(q + ex) - field_anywhere(q - ex), field_anywhere(q + ey) - field_anywhere(q - ey),
                field_anywhere(q + ez) - field_anywhere(q - ez));
}

// The crossing between ta (F below iso) and tb (F at or above it), both in the current brick.
float refine(float ta, float fa, float tb, float fb) {
    for (int i = 0; i < u_refine; ++i) {
        float tm = 0.5 * (ta + tb);
        float fm = field(tm);
        if (fm >= u_iso) {
            tb = tm;
            fb = fm;
        } else {
            ta = tm;
            fa = fm;
        }
    }
    return mix(ta, tb, clamp((u_iso - fa) / max(fb - fa, 1e-30), 0.0, 1.0));
}

// How much of [ta, tb] lies inside (F >= iso), F taken as linear between the ends.
float inside_length(float ta, float fa, float tb, float fb) {
    bool a = fa >= u_iso, b = fb >= u_iso;
    if (a == b) return a ? tb - ta : 0.0;
    float c = (u_iso - fa) / (fb - fa);
    return (a ? c : 1.0 - c) * (tb - ta);
}

float march_inside(float ta, float fa, float tb, float dt) {
    float sum = 0.0;
    for (int k = 0; k < 4096 && ta < tb; ++k) {
        float s = min(ta + dt, tb);
        float f = field(s);
        sum += inside_length(ta, fa, s, f);
        ta = s;
        fa = f;
    }
    return sum;
}

// The walk's next brick; false once it leaves the grid.
bool advance(inout ivec3 cell, inout vec3 next, ivec3 dir, vec3 delta) {
    if (next.x <= next.y && next.x <= next.z) {
        cell.x += dir.x;
        next.x += delta.x;
    } else if (next.y <= next.z) {
        cell.y += dir.y;
        next.y += delta.y;
    } else {
        cell.z += dir.z;
        next.z += delta.z;
    }
    return all(greaterThanEqual(cell, ivec3(0))) && all(lessThan(cell, u_grid));
}

float exit_of(vec3 next, float t, float t1) {
    return max(t, min(min(next.x, next.y), min(next.z, t1)));
}

void main() {
    vec3 ray = pixel_ray(gl_FragCoord.xy);
    g_o = (u_eye - u_origin) / u_voxel;
    g_d = ray / u_voxel;
    // An axis the ray runs parallel to gets a tiny component, so slabs and walk stay finite.
    vec3 safe_d = mix(vec3(-1.0), vec3(1.0), greaterThanEqual(g_d, vec3(0.0))) * max(abs(g_d), vec3(1e-12));
    vec3 inv = 1.0 / safe_d;
    vec3 ta = (u_ray_lo - g_o) * inv, tb = (u_ray_hi - g_o) * inv;
    vec3 tn = min(ta, tb), tf = max(ta, tb);
    float t0 = max(max(tn.x, tn.y), max(tn.z, u_near_far.x));
    float t1 = min(min(tf.x, tf.y), min(tf.z, scene_eye_depth(ivec2(gl_FragCoord.xy))));
    float len = length(g_d);  // lattice units per unit of t
    if (u_use_span) {
        // Widened by a voxel: the rasteriser's faces and the ray's slabs round differently.
        vec2 span = texelFetch(u_span, ivec2(gl_FragCoord.xy), 0).rg;
        t0 = max(t0, -span.x - 1.0 / len);
        t1 = min(t1, span.y + 1.0 / len);
    }
    if (!(t0 < t1)) discard;

    float cells = float(kBrickCells);
    ivec3 dir = ivec3(sign(safe_d));
    ivec3 cell = clamp(ivec3(floor((g_o + t0 * g_d) / cells)), ivec3(0), u_grid - 1);
    vec3 next = (vec3(cell + max(dir, ivec3(0))) * cells - g_o) * inv;  // where the ray leaves it, per axis
    vec3 delta = cells * abs(inv);

    float dt = u_step / len;
    float t = t0, t_exit = t0, t_hit = 0.0;
    bool have_prev = false, hit = false;
    float prev_t = t0, prev_f = 0.0;
    int walked = 0;
    for (; walked < u_max_bricks; ++walked) {
        t_exit = exit_of(next, t, t1);
        vec4 info = texelFetch(u_bricks, cell, 0);
        if (info.x >= 0.0 && info.z >= u_iso) {
            enter_brick(cell, info.x);
            // The last brick's final sample lies on the face this one shares with it: same value.
            if (!have_prev || prev_t < t) {
                prev_t = t;
                prev_f = field(t);
                have_prev = true;
                if (prev_f >= u_iso) {
                    t_hit = t;
                    hit = true;
                    break;
                }
            }
            for (int k = 0; k < 4096 && prev_t < t_exit; ++k) {
                float s = min(prev_t + dt, t_exit);
                float f = field(s);
                if (f >= u_iso) {
                    t_hit = refine(prev_t, prev_f, s, f);
                    hit = true;
                    break;
                }
                prev_t = s;
                prev_f = f;
            }
            if (hit) break;
        } else {
            have_prev = false;
        }
        if (t_exit >= t1) break;
        t = t_exit;
        if (!advance(cell, next, dir, delta)) break;
    }
    if (!hit) discard;

    vec3 grad = gradient(g_o + t_hit * g_d);

    // Thickness: from the surface on, until the scene, the grid's end, or the absorption saturates.
    float tdt = u_thickness_step / len;
    float cap = u_thickness_cap / length(ray);
    float inside = march_inside(t_hit, u_iso, t_exit, tdt);
    for (++walked; walked < u_max_bricks && inside < cap && t_exit < t1; ++walked) {
        t = t_exit;
        if (!advance(cell, next, dir, delta)) break;
        t_exit = exit_of(next, t, t1);
        vec4 info = texelFetch(u_bricks, cell, 0);
        if (info.x < 0.0 || info.z < u_iso) continue;  // no water in it
        if (info.y >= u_iso) {
            inside += t_exit - t;
        } else {
            enter_brick(cell, info.x);
            inside += march_inside(t, field(t), t_exit, tdt);
        }
    }
    float thickness = min(inside * length(ray), u_thickness_cap);

    vec3 v = -normalize(ray);
    vec3 n = dot(grad, grad) > 0.0 ? -normalize(grad) : v;
    if (dot(n, v) < 0.0) n = -n;
    vec2 uv = gl_FragCoord.xy / u_viewport;
    vec3 r = reflect(-v, n);
    vec3 reflected = u_has_environment ? textureLod(u_environment, r, u_reflection_lod).rgb : sky_color(r);
    float highlight = pow(max(dot(n, normalize(u_light_dir + v)), 0.0), 96.0);
    vec3 color = shade_water(n, v, reflected, thickness, uv, vec2(dot(n, u_right), dot(n, u_up)), highlight,
                             water_window_depth(t_hit, u_near_far));
    frag_color = vec4(color, 1.0);
    frag_depth = t_hit;
    frag_thickness = thickness;
}
)";

}  // namespace rivulet::shaders
