// One water for every surface method (Janisz §3.1.4): the shading function against its formulas, the
// mesh methods' thickness against box geometry, and the three methods' coverage of one frame.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "runtime/lib/frame_pipeline.h"
#include "runtime/lib/thread_control.h"
#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/gl_program.h"
#include "systems/render/osmesa_context.h"
#include "systems/render/renderer.h"
#include "systems/render/shaders.h"

namespace rivulet {
namespace {

// --- shade_water, evaluated by the driver for one pixel ---

const char* const kProbeFragment = R"(
uniform vec3 u_n;
uniform vec3 u_v;
uniform vec3 u_reflected;
uniform float u_thick;
uniform vec2 u_uv;
uniform vec2 u_n_screen;
uniform float u_front_z;
uniform float u_eye_depth;
uniform vec2 u_near_far;
out vec4 frag_color;
void main() {
    frag_color = vec4(shade_water(u_n, u_v, u_reflected, u_thick, u_uv, u_n_screen, 0.0, u_front_z),
                      water_window_depth(u_eye_depth, u_near_far));
}
)";

// The scene behind is one row of kSceneTexels: `behind` from the middle texel on, `beside` (with its own
// window depth) left of it. The probe's pixel is the middle texel's centre, so a refraction offset to the
// left reads `beside`.
constexpr int kSceneTexels = 32;

struct WaterInputs {
    Vec3f n{0, 0, 1}, v{0, 0, 1}, reflected, behind, beside, water_color, absorption{9, 3.5f, 1.6f};
    float thickness = 0;
    float n_screen_x = 0;                              // the normal's part along the screen's x
    float front_z = 0.5f, behind_z = 1, beside_z = 1;  // window depths: the water's, the scene's
};

class ShadeWaterProbe {
  public:
    ShadeWaterProbe() : context_(16, 16) {
        const GLuint vs = compile_shader(GL_VERTEX_SHADER, {shaders::kFullScreenVertex}, "probe.vert");
        const GLuint fs =
            compile_shader(GL_FRAGMENT_SHADER,
                           {shaders::kFragmentPrelude, shaders::kWaterShading, kProbeFragment}, "probe.frag");
        program_ = link_program(vs, fs, "probe");
        glGenTextures(3, textures_);
        glBindTexture(GL_TEXTURE_2D, textures_[0]);  // the scene behind
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, kSceneTexels, 1);
        glBindTexture(GL_TEXTURE_2D, textures_[1]);  // its window depth
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_R32F, kSceneTexels, 1);
        glBindTexture(GL_TEXTURE_2D, textures_[2]);  // the result
        glTexStorage2D(GL_TEXTURE_2D, 1, GL_RGBA32F, 1, 1);
        glGenFramebuffers(1, &fbo_);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, textures_[2], 0);
        glGenVertexArrays(1, &vao_);
        check_gl("probe setup");
    }
    ~ShadeWaterProbe() {
        glDeleteProgram(program_);
        glDeleteTextures(3, textures_);
        glDeleteFramebuffers(1, &fbo_);
        glDeleteVertexArrays(1, &vao_);
    }

    Vec3f shade(const WaterInputs& in) {
        const auto set3 = [&](const char* name, Vec3f v) {
            glProgramUniform3f(program_, glGetUniformLocation(program_, name), v.x, v.y, v.z);
        };
        set3("u_n", in.n), set3("u_v", in.v), set3("u_reflected", in.reflected);
        set3("u_water_color", in.water_color), set3("u_absorption", in.absorption);
        glProgramUniform1f(program_, glGetUniformLocation(program_, "u_thick"), in.thickness);
        glProgramUniform1f(program_, glGetUniformLocation(program_, "u_refraction"), shaders::kRefraction);
        glProgramUniform1f(program_, glGetUniformLocation(program_, "u_front_z"), in.front_z);
        glProgramUniform2f(program_, glGetUniformLocation(program_, "u_n_screen"), in.n_screen_x, 0);
        glProgramUniform2f(program_, glGetUniformLocation(program_, "u_uv"),
                           (kSceneTexels / 2 + 0.5f) / kSceneTexels, 0.5f);
        glProgramUniform1i(program_, glGetUniformLocation(program_, "u_scene_color"), 0);
        glProgramUniform1i(program_, glGetUniformLocation(program_, "u_scene_depth"), 1);
        std::vector<float> color, depth;
        for (int i = 0; i < kSceneTexels; ++i) {
            const bool right = i >= kSceneTexels / 2;
            const Vec3f c = right ? in.behind : in.beside;
            color.insert(color.end(), {c.x, c.y, c.z, 1});
            depth.push_back(right ? in.behind_z : in.beside_z);
        }
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, textures_[0]);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, kSceneTexels, 1, GL_RGBA, GL_FLOAT, color.data());
        glActiveTexture(GL_TEXTURE1);
        glBindTexture(GL_TEXTURE_2D, textures_[1]);
        glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, kSceneTexels, 1, GL_RED, GL_FLOAT, depth.data());
        glActiveTexture(GL_TEXTURE0);
        const std::array<float, 4> out = draw();
        return {out[0], out[1], out[2]};
    }

    // water_window_depth at view depth d for the camera's near and far planes.
    float window_depth(float d) {
        glProgramUniform1f(program_, glGetUniformLocation(program_, "u_eye_depth"), d);
        glProgramUniform2f(program_, glGetUniformLocation(program_, "u_near_far"), kCameraNear, kCameraFar);
        return draw()[3];
    }

  private:
    std::array<float, 4> draw() {
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glViewport(0, 0, 1, 1);
        glUseProgram(program_);
        glBindVertexArray(vao_);
        glDrawArrays(GL_TRIANGLES, 0, 3);
        std::array<float, 4> out{};
        glReadPixels(0, 0, 1, 1, GL_RGBA, GL_FLOAT, out.data());
        check_gl("probe draw");
        return out;
    }

    OsMesaContext context_;
    GLuint program_ = 0, textures_[3] = {}, fbo_ = 0, vao_ = 0;
};

constexpr float kF0 = 0.02f;  // water's reflectance at normal incidence

TEST(WaterShading, FresnelReflectsF0AtNormalIncidenceAndEverythingAtGrazing) {
    ShadeWaterProbe probe;
    WaterInputs in;
    in.reflected = {1, 1, 1};  // a white environment over a black scene, through no water
    const Vec3f normal = probe.shade(in);
    for (float c : {normal.x, normal.y, normal.z}) EXPECT_NEAR(c, kF0, 1e-5f);
    in.v = {1, 0, 0};  // the view grazes the surface
    const Vec3f grazing = probe.shade(in);
    for (float c : {grazing.x, grazing.y, grazing.z}) EXPECT_NEAR(c, 1.0f, 1e-5f);
    // Schlick in between: at 60 degrees, F0 + (1 - F0) (1 - cos)^5.
    in.v = {std::sqrt(3.0f) / 2, 0, 0.5f};
    EXPECT_NEAR(probe.shade(in).x, kF0 + (1 - kF0) * std::pow(0.5f, 5.0f), 1e-5f);
}

TEST(WaterShading, LightFromBehindFallsByBeerLambertOverTheThickness) {
    ShadeWaterProbe probe;
    WaterInputs in;
    in.behind = {1, 1, 1};  // white behind, black water colour and environment
    for (float t : {0.0f, 0.05f, 0.1f, 0.4f}) {
        in.thickness = t;
        const Vec3f c = probe.shade(in);
        EXPECT_NEAR(c.x, (1 - kF0) * std::exp(-in.absorption.x * t), 1e-5f) << "thickness " << t;
        EXPECT_NEAR(c.y, (1 - kF0) * std::exp(-in.absorption.y * t), 1e-5f) << "thickness " << t;
        EXPECT_NEAR(c.z, (1 - kF0) * std::exp(-in.absorption.z * t), 1e-5f) << "thickness " << t;
    }
    // Thick water shows its own colour.
    in.water_color = {0.1f, 0.3f, 0.5f};
    in.thickness = 50;
    const Vec3f deep = probe.shade(in);
    EXPECT_NEAR(deep.x, (1 - kF0) * 0.1f, 1e-4f);
    EXPECT_NEAR(deep.z, (1 - kF0) * 0.5f, 1e-4f);
}

TEST(WaterShading, RefractionShowsTheSceneBehindButNotWhatStandsInFront) {
    ShadeWaterProbe probe;
    WaterInputs in;
    in.behind = {1, 1, 1};  // white under the pixel, black beside it, clear water, a black sky
    in.absorption = {0, 0, 0};
    in.thickness = 0.2f;
    in.n_screen_x = 1;  // the lookup moves kRefraction * 0.2 = 1.6 texels left, onto the black
    ASSERT_GT(shaders::kRefraction * in.thickness * kSceneTexels, 1.0f);
    in.beside_z = 0.9f;  // behind the water's front: refracted into view
    EXPECT_NEAR(probe.shade(in).x, 0.0f, 1e-5f);
    in.beside_z = 0.2f;  // in front of the water (a post of the tank's frame): the scene under the pixel
    EXPECT_NEAR(probe.shade(in).x, 1 - kF0, 1e-5f);
    in.n_screen_x = 0;  // facing the eye: no offset, whatever stands beside
    in.beside_z = 0.9f;
    EXPECT_NEAR(probe.shade(in).x, 1 - kF0, 1e-5f);
}

// The composite and the volume's rays know their water's depth along the view axis; the mask compares
// it with the scene's depth buffer, so it must land where the camera's projection puts that depth.
TEST(WaterShading, WindowDepthIsTheCamerasProjectionOfAViewDepth) {
    ShadeWaterProbe probe;
    const Mat4 projection = perspective(0.5f, 16.0f / 9.0f);
    for (float d : {0.1f, 1.0f, 3.5f, 20.0f, 90.0f}) {
        const Eigen::Vector4f clip = projection * Eigen::Vector4f(0, 0, -d, 1);
        const float window = 0.5f + 0.5f * clip.z() / clip.w();
        EXPECT_NEAR(probe.window_depth(d), window, 2e-6f) << "view depth " << d;
    }
}

// --- the mesh methods' thickness ---

constexpr int kW = 320, kH = 240;

SceneDesc axis_scene() {
    SceneDesc s;
    s.camera.eye = {0, 0, 3};
    s.camera.target = {0, 0, 0};
    s.ground_y = -5;
    return s;
}

struct Meshes {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
    void add(const test::BoxMesh& m) {
        const auto base = static_cast<std::uint32_t>(vertices.size() / 6);
        vertices.insert(vertices.end(), m.vertices.begin(), m.vertices.end());
        for (std::uint32_t i : m.indices) indices.push_back(base + i);
    }
};

// The thickness at the pixel `world` projects to, read from the renderer's reduced-size target.
class ThicknessPicture {
  public:
    ThicknessPicture(Renderer& r, const Meshes& m, const SceneDesc& scene) : camera_(scene.camera) {
        r.set_scene(scene);
        FrameView frame;
        frame.mesh = {m.vertices, m.indices};
        r.render(frame);
        const WaterBackdrop& w = r.water_backdrop();
        tw_ = w.thickness_width();
        th_ = w.thickness_height();
        values_.resize(std::size_t(tw_) * std::size_t(th_));
        w.read_thickness(values_);
    }
    float at_world(Vec3f world) const {
        float px = 0, py = 0;
        EXPECT_TRUE(project_to_pixel(camera_, kW, kH, world, px, py));
        const int x = static_cast<int>(px) / WaterBackdrop::kThicknessDownsample;
        const int y = (kH - 1 - static_cast<int>(py)) / WaterBackdrop::kThicknessDownsample;
        return values_[std::size_t(y) * std::size_t(tw_) + std::size_t(x)];
    }

  private:
    CameraDesc camera_;
    int tw_ = 0, th_ = 0;
    std::vector<float> values_;
};

TEST(MeshWater, ThicknessOfABoxIsThePathThroughIt) {
    Renderer r(RenderSettings{kW, kH});
    Meshes m;
    m.add(test::box_mesh({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}));
    const ThicknessPicture t(r, m, axis_scene());
    // Rays from the eye through points of the front face leave through the back face: the path is the
    // ray's length between z = 0.5 and z = -0.5.
    const Vec3f eye{0, 0, 3};
    for (Vec3f front : {Vec3f{0, 0, 0.5f}, Vec3f{0.2f, 0.1f, 0.5f}, Vec3f{-0.25f, 0.2f, 0.5f}}) {
        const Vec3f d = front - eye;
        const float path = 1.0f / 2.5f * std::sqrt(dot(d, d));
        EXPECT_NEAR(t.at_world(front), path, 0.02f * path) << front.x << ", " << front.y;
    }
    // Outside the box's outline there is no water.
    EXPECT_EQ(t.at_world({0.9f, 0.0f, 0.5f}), 0.0f);
}

TEST(MeshWater, TwoBoxesOnOneRaySumTheirWaterNotTheGapBetween) {
    Renderer r(RenderSettings{kW, kH});
    Meshes m;
    m.add(test::box_mesh({-0.5f, -0.5f, 0.2f}, {0.5f, 0.5f, 0.5f}));
    m.add(test::box_mesh({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, -0.2f}));
    const ThicknessPicture t(r, m, axis_scene());
    EXPECT_NEAR(t.at_world({0, 0, 0.5f}), 0.6f, 0.012f);
}

TEST(MeshWater, OverlappingClosedSurfacesCountTheirWaterOnce) {
    // Scan conversion's cylinders and spheres overlap; the sum would count the shared water twice.
    Renderer r(RenderSettings{kW, kH});
    Meshes m;
    m.add(test::box_mesh({-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.3f}));
    m.add(test::box_mesh({-0.4f, -0.4f, -0.3f}, {0.4f, 0.4f, 0.5f}));
    const ThicknessPicture t(r, m, axis_scene());
    EXPECT_NEAR(t.at_world({0, 0, 0.5f}), 1.0f, 0.02f);
}

TEST(MeshWater, AnIsolatedSphereIsAsThickAsItsChord) {
    // Scan conversion's isolated spheres are measured as round points, not as their low-res meshes.
    Renderer r(RenderSettings{kW, kH});
    const SceneDesc scene = axis_scene();
    r.set_scene(scene);
    const float centre[3] = {0, 0, 0}, radius = 0.3f;
    FrameView frame;
    frame.sphere_centers = centre;
    frame.sphere_radius = radius;
    r.render(frame);
    const WaterBackdrop& w = r.water_backdrop();
    const int tw = w.thickness_width(), th = w.thickness_height();
    std::vector<float> t(std::size_t(tw) * std::size_t(th));
    w.read_thickness(t);
    // Every texel against the chord of the ray through its centre.
    const CameraBasis b = camera_basis(scene.camera);
    const float aspect = float(kW) / float(kH);
    int inside = 0;
    for (int y = 0; y < th; ++y)
        for (int x = 0; x < tw; ++x) {
            const float nx = (float(x) + 0.5f) / float(tw) * 2 - 1,
                        ny = (float(y) + 0.5f) / float(th) * 2 - 1;
            const Vec3f dir = normalize(b.forward + b.right * (nx * b.tan_half_fov_y * aspect) +
                                        b.up * (ny * b.tan_half_fov_y));
            const float bb = dot(b.eye, dir), c = dot(b.eye, b.eye) - radius * radius;
            const float disc = bb * bb - c;
            const float want = disc > 0 ? 2 * std::sqrt(disc) : 0.0f;
            const float got = t[std::size_t(y) * std::size_t(tw) + std::size_t(x)];
            // At the outline the point's coverage and the analytic test may disagree by a texel.
            if (want > 0.2f * radius) {
                ++inside;
                ASSERT_NEAR(got, want, 1e-3f) << x << ", " << y;
            } else if (disc < -0.01f * radius * radius) {
                ASSERT_EQ(got, 0.0f) << x << ", " << y;
            }
        }
    EXPECT_GT(inside, 100);
}

// --- one frame, three methods ---

// Opaque magenta water: every pixel the surface covers is told apart from the scene, whichever method
// drew it, and its shadow on the ground is not.
std::vector<bool> water_coverage(SurfaceMethod method, std::size_t& count) {
    ThreadControl control(2);
    PipelineSettings config;
    config.size = {320, 180};
    config.method = method;
    SceneDesc scene = make_builtin_scene("fountain");
    scene.warmup_frames = 60;
    scene.pool.enabled = false;  // the pool is the same in every method: only the streams are compared
    scene.look.water.color = {1, 0, 1};
    scene.look.water.absorption = {500, 500, 500};
    FramePipeline pipeline(scene, config);
    pipeline.warmup();
    pipeline.run(1);
    std::vector<std::uint8_t> rgba(320 * 180 * 4);
    pipeline.renderer()->read_rgba(rgba);
    std::vector<bool> mask(320 * 180);
    count = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        const int r = rgba[4 * i], g = rgba[4 * i + 1], b = rgba[4 * i + 2];
        mask[i] = r > g + 60 && b > g + 60;
        count += mask[i] ? 1 : 0;
    }
    return mask;
}

// Pixels covered by one method and not the other, over those covered by either.
double disagreement(const std::vector<bool>& a, const std::vector<bool>& b) {
    std::size_t either = 0, one = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        either += (a[i] || b[i]) ? 1 : 0;
        one += (a[i] != b[i]) ? 1 : 0;
    }
    return either ? double(one) / double(either) : 1.0;
}

TEST(WaterComposite, TheThreeMethodsCoverTheSamePixelsOfOneFrame) {
    std::size_t scan_n = 0, slices_n = 0, screen_n = 0;
    const std::vector<bool> scan = water_coverage(SurfaceMethod::kScan, scan_n);
    const std::vector<bool> slices = water_coverage(SurfaceMethod::kSlices, slices_n);
    const std::vector<bool> screen = water_coverage(SurfaceMethod::kScreen, screen_n);
    for (std::size_t n : {scan_n, slices_n, screen_n}) EXPECT_GT(n, 2000u);
    // The surfaces differ by how far they reach past the particles (scan conversion's round cylinders
    // most): the silhouettes' outlines disagree, the bodies agree.
    EXPECT_LT(disagreement(screen, slices), 0.25) << screen_n << " vs " << slices_n << " pixels";
    EXPECT_LT(disagreement(screen, scan), 0.25) << screen_n << " vs " << scan_n << " pixels";
    EXPECT_LT(disagreement(slices, scan), 0.30) << slices_n << " vs " << scan_n << " pixels";
}

TEST(WaterComposite, PicturesAreTheSameBytesAtOneAndTwoThreads) {
    // The thickness is blended in float in primitive order, which llvmpipe keeps at any thread count.
    for (SurfaceMethod method : {SurfaceMethod::kScan, SurfaceMethod::kSlices, SurfaceMethod::kScreen}) {
        std::vector<std::vector<std::uint8_t>> pictures;
        for (int threads : {1, 2}) {
            ThreadControl control(threads);
            PipelineSettings config;
            config.method = method;
            config.size = {160, 90};
            SceneDesc scene = make_builtin_scene("fountain");
            scene.warmup_frames = 40;
            FramePipeline pipeline(scene, config);
            pipeline.warmup();
            pipeline.run(2);
            pictures.emplace_back(std::size_t(160) * 90 * 4);
            pipeline.renderer()->read_rgba(pictures.back());
        }
        EXPECT_TRUE(pictures[0] == pictures[1]) << surface_method_name(method);
    }
}

}  // namespace
}  // namespace rivulet
