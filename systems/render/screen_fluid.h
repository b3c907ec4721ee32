#pragma once
// Screen-space fluid rendering (van der Laan, Green & Sainz 2009; Janisz §3.1): particles are drawn as
// spheres into a linear eye-space depth target; the depth is smoothed (a separable bilateral filter,
// curvature flow, or the narrow-range filter of Truong & Yuksel 2018) with a screen radius that follows
// depth; the fluid's thickness is summed at reduced resolution and blurred; and a composite pass shades
// the water from normals of the smoothed depth over the scene already drawn. Runs on the render thread,
// inside the Renderer's GL context.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "systems/render/frame_view.h"
#include "systems/scenes/scene.h"
#include "systems/scenes/scene_look.h"

namespace rivulet {

// How the depth is smoothed (Janisz §3.1.2 and beyond it).
enum class DepthSmoothing {
    kBilateral,      // separable bilateral approximation (van Vliet & Pham), Gaussian over depth differences
    kCurvatureFlow,  // mean-curvature flow of the depth (van der Laan, Green & Sainz 2009)
    kNarrowRange,    // narrow-range filter (Truong & Yuksel 2018): a hard, growing depth range, no halos
};
// "bilateral", "curvature-flow", "narrow-range"; parse returns false on anything else.
const char* depth_smoothing_name(DepthSmoothing s);
bool parse_depth_smoothing(std::string_view text, DepthSmoothing& out);
// Passes a smoothing takes by default; a filter's passes share its width (n passes of sigma / sqrt(n)).
// The narrow-range filter takes two: in one separable pass each direction's kernel stops where a
// nearer sheet begins, which leaves the farther sheet next to that edge less smoothed in axis-aligned
// steps, and the refraction shows them as blocks; a second pass smooths them over (tested), for 1.5-1.7x
// the smoothing's time. The bilateral filter takes one: its depth weights let a little of a nearer
// sheet through, and more passes spread that. Curvature flow moves the surface a little per step, so it
// needs many.
int default_filter_iterations(DepthSmoothing s);

struct ScreenFluidSettings {
    static constexpr int kMaxIterations = 256;
    DepthSmoothing smoothing = DepthSmoothing::kNarrowRange;
    // Filter passes (each one x and one y) or curvature-flow steps; the filters' passes share the width
    // (default_filter_iterations).
    int filter_iterations = default_filter_iterations(smoothing);
    // The smoothing's Gaussian sigma over the image, all passes together, in particle radii at the
    // pixel's depth.
    float filter_radius = 2.0f;
    // In particle radii: the bilateral's Gaussian sigma over depth differences, the narrow-range filter's
    // starting half range, and the depth jump curvature flow treats as another surface.
    float depth_sigma = 4.0f;
    int max_filter_pixels = 16;  // the filter's half width never exceeds this
    // The filters read at most this many taps on each side; wider kernels are sampled with a stride.
    // By default every pixel of the widest kernel: with a stride, neighbouring pixels read disjoint
    // sets of the particles' bumps and the filters' depth decisions differ between them: the depth
    // comes out hatched, and the composite's refraction turns that into speckle (perf/RESULTS.md).
    int max_filter_taps = 16;
    int fill_holes = 2;  // background pixels with fluid on both sides this near are filled (0: none)
    int thickness_downsample = 2;
    float thickness_blur = 1.5f;  // Gaussian sigma over the thickness, in its reduced pixels (0: none)
    // Spray (Green, GDC 2010): particles with fewer than this many others within spray_distance are
    // drawn as small bright sprites instead of water (0: no spray). Two spacings around a particle hold
    // about 32 others inside water, 22 at a flat surface and 12 in a one-layer sheet, but 4 along a thin
    // filament: below 6 a particle is a drop or a strand, not part of a surface.
    static constexpr int kMaxSprayNeighbours = 64;
    int spray_neighbours = 6;
    float spray_distance = 4.0f;  // particle radii: two SPH spacings (SPH particles sit 2 radii apart)
    bool time_passes = false;     // finish GL after each pass and time it (benchmarks; slows the frame)
    // "" when valid, else the problem naming the option (--filter-iterations, ...).
    std::string validate() const;
};

// Milliseconds of each pass of the last render (with ScreenFluidSettings::time_passes; else zeros).
struct ScreenFluidTimings {
    double copy_scene = 0, depth = 0, smoothing = 0, thickness = 0, composite = 0, spray = 0;
};

// The passes' targets, for tests.
enum class ScreenFluidBuffer { kRawDepth, kSmoothedDepth, kThickness };

// The radius of the spheres the depth pass draws for particles of `radius` that sit `spacing` apart:
// the spacing, within [radius, 2 radius] (`radius` where the spacing is unknown, 0, or smaller). SPH
// particles are spheres of half their spacing, and rays slip between spheres that small, so the depth
// read as sand, and the smoothing, which keeps a deeper pixel as another surface, left it in streaks.
// Spheres of the spacing's radius overlap their neighbours; each hit is pushed back along the view by
// the radii's difference, so a flat surface seen face on stays about one radius outside the outer
// centres (on a square lattice 0.82 r on average at spacing 2 r, 0.91 r at spacing r, where the spheres
// are drawn as they are: the tops dip between centres). At most 2 radii, so that separate drops do not
// merge; outlines grow by the difference.
float screen_depth_radius(float radius, float spacing);

class ScreenFluidPass {
  public:
    // Allocates its targets for a width x height picture; throws std::runtime_error on a GL failure or
    // std::invalid_argument on bad settings.
    ScreenFluidPass(int width, int height, const ScreenFluidSettings& settings);
    ~ScreenFluidPass();
    ScreenFluidPass(const ScreenFluidPass&) = delete;
    ScreenFluidPass& operator=(const ScreenFluidPass&) = delete;

    void set_camera(const CameraDesc& camera, Vec3f light_dir);
    void set_water(const WaterLook& water);
    // A GL cube-map texture the water reflects (the Renderer's environment); 0: the analytic sky.
    void set_environment(unsigned cube_map_texture);
    // Draws `particles` (spheres of `radius`) as water over the picture in the default framebuffer,
    // whose colour and depth are the scene behind. No particles: the picture is left as it is.
    // `spacing`: the particles' spacing (0: unknown), which sets the depth pass's spheres
    // (screen_depth_radius).
    void render(const ParticleSpritesView& particles, float radius, float spacing = 0);
    // The same, then `spray` drawn over the water as small bright sprites of about 0.6 x a particle's
    // size, hidden by solids in front and by the water's surface.
    void render(const ParticleSpritesView& fluid, const ParticleSpritesView& spray, float radius,
                float spacing = 0);
    // Width x height floats (thickness: its reduced size, thickness_size()), rows bottom to top.
    void read(ScreenFluidBuffer which, std::span<float> out) const;
    const ScreenFluidTimings& timings() const;
    int thickness_width() const;
    int thickness_height() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace rivulet
