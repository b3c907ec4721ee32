// Scene dressing on real pixels: the environment cube map (made and loaded), the key light's shadows,
// the SPH tank's frame and glass, and the scene files' "look".
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/environment_map.h"
#include "systems/render/png_writer.h"
#include "systems/render/renderer.h"
#include "systems/render/scene_geometry.h"
#include "systems/render/shadow_map.h"
#include "systems/scenes/scene_json.h"

namespace rivulet {
namespace {

constexpr int kW = 320, kH = 240;

struct Rgb {
    int r = 0, g = 0, b = 0;
    int sum() const { return r + g + b; }
    bool operator==(const Rgb&) const = default;
};

class Picture {
  public:
    explicit Picture(const Renderer& r)
        : w_(r.width()), h_(r.height()), rgba_(std::size_t(r.width()) * r.height() * 4u) {
        r.read_rgba(rgba_);
    }
    Rgb at(int x, int y) const {
        const std::uint8_t* p = &rgba_[(std::size_t(y) * w_ + x) * 4u];
        return {p[0], p[1], p[2]};
    }
    Rgb at_world(const CameraDesc& cam, Vec3f world) const {
        float px = 0, py = 0;
        EXPECT_TRUE(project_to_pixel(cam, w_, h_, world, px, py));
        return at(static_cast<int>(px), static_cast<int>(py));
    }
    int width() const { return w_; }
    int height() const { return h_; }

  private:
    int w_, h_;
    std::vector<std::uint8_t> rgba_;
};

// With RIVULET_TEST_PICTURES=DIR set, the pictures the tests judge are written there to be looked at.
void keep_picture(const Renderer& r, const std::string& name) {
    const char* dir = std::getenv("RIVULET_TEST_PICTURES");
    if (!dir) return;
    std::vector<std::uint8_t> rgba(std::size_t(r.width()) * r.height() * 4u);
    r.read_rgba(rgba);
    write_png_rgba(std::string(dir) + "/" + name + ".png", r.width(), r.height(), rgba);
}

int channel_error(Rgb c, Vec3f expected) {
    const auto e = [](int v, float f) { return std::abs(v - static_cast<int>(std::lround(f * 255.0f))); };
    return std::max({e(c.r, expected.x), e(c.g, expected.y), e(c.b, expected.z)});
}

// The ray from the eye through the centre of pixel (x, y) (rows from the top), as the renderer's
// perspective projection draws it.
Vec3f pixel_ray(const CameraDesc& cam, int x, int y) {
    const CameraBasis b = camera_basis(cam);
    const float aspect = float(kW) / float(kH);
    const float sx = (2.0f * (float(x) + 0.5f) / float(kW) - 1.0f) * b.tan_half_fov_y * aspect;
    const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(kH)) * b.tan_half_fov_y;
    return normalize(b.forward + b.right * sx + b.up * sy);
}

bool ray_hits_sphere(Vec3f origin, Vec3f dir, Vec3f center, float radius) {
    const Vec3f oc = origin - center;
    const float b = dot(oc, dir), c = dot(oc, oc) - radius * radius;
    return b * b - c >= 0 && (-b + std::sqrt(std::max(b * b - c, 0.0f))) > 0;
}

// A UV sphere as a generic mesh (6 floats per vertex).
struct SphereMesh {
    std::vector<float> vertices;
    std::vector<std::uint32_t> indices;
};
SphereMesh sphere_mesh(Vec3f c, float r) {
    constexpr std::uint32_t kSlices = 48, kStacks = 32;
    SphereMesh m;
    for (std::uint32_t i = 0; i <= kStacks; ++i) {
        const float th = std::numbers::pi_v<float> * float(i) / kStacks;
        for (std::uint32_t j = 0; j <= kSlices; ++j) {
            const float ph = 2 * std::numbers::pi_v<float> * float(j) / kSlices;
            const Vec3f n{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
            const Vec3f p = c + n * r;
            m.vertices.insert(m.vertices.end(), {p.x, p.y, p.z, n.x, n.y, n.z});
        }
    }
    for (std::uint32_t i = 0; i < kStacks; ++i)
        for (std::uint32_t j = 0; j < kSlices; ++j) {
            const std::uint32_t a = i * (kSlices + 1) + j, b = a + kSlices + 1;
            m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
    return m;
}

// Face and (s, t) of a direction by the major-axis table of the OpenGL specification (8.13), written
// independently of cube_face_direction.
void gl_cube_lookup(Vec3f d, int& face, float& s, float& t) {
    const float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    float sc = 0, tc = 0, ma = 0;
    if (ax >= ay && ax >= az) {
        face = d.x > 0 ? 0 : 1, ma = ax, sc = d.x > 0 ? -d.z : d.z, tc = -d.y;
    } else if (ay >= az) {
        face = d.y > 0 ? 2 : 3, ma = ay, sc = d.x, tc = d.y > 0 ? d.z : -d.z;
    } else {
        face = d.z > 0 ? 4 : 5, ma = az, sc = d.z > 0 ? d.x : -d.x, tc = -d.y;
    }
    s = 0.5f * (sc / ma + 1), t = 0.5f * (tc / ma + 1);
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "no error";
}

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
    if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << "'" << text << "' does not contain '" << part << "'";
}

void write_solid_png(const std::string& path, int w, int h, Rgb c) {
    std::vector<std::uint8_t> rgba(std::size_t(w) * h * 4u);
    for (std::size_t i = 0; i < rgba.size(); i += 4)
        rgba[i] = std::uint8_t(c.r), rgba[i + 1] = std::uint8_t(c.g), rgba[i + 2] = std::uint8_t(c.b),
        rgba[i + 3] = 255;
    write_png_rgba(path, w, h, rgba);
}

const std::array<Rgb, 6> kFaceColors = {
    {{200, 30, 30}, {30, 200, 30}, {30, 30, 200}, {200, 200, 30}, {200, 30, 200}, {30, 200, 200}}};

// Six solid faces in a fresh directory, named px.png ... nz.png; returns their paths.
std::vector<std::string> solid_faces(const std::string& dir_name, int size = 16) {
    const std::string dir = test::temp_path(dir_name);
    std::filesystem::create_directories(dir);
    const char* names[6] = {"px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"};
    std::vector<std::string> paths;
    for (int f = 0; f < 6; ++f) {
        paths.push_back(dir + "/" + names[f]);
        write_solid_png(paths.back(), size, size, kFaceColors[std::size_t(f)]);
    }
    return paths;
}

SceneDesc open_scene(Vec3f eye, Vec3f target) {
    SceneDesc s;
    s.camera = {eye, target, 45};
    return s;
}

// --- environment ---

TEST(CubeFaces, DirectionsFollowTheGlConvention) {
    for (int face = 0; face < 6; ++face) {
        for (float s : {0.1f, 0.5f, 0.83f}) {
            for (float t : {0.07f, 0.5f, 0.9f}) {
                const Vec3f d = cube_face_direction(face, s, t);
                EXPECT_NEAR(length(d), 1.0f, 1e-5f);
                int f2 = -1;
                float s2 = 0, t2 = 0;
                gl_cube_lookup(d, f2, s2, t2);
                EXPECT_EQ(f2, face);
                EXPECT_NEAR(s2, s, 1e-5f);
                EXPECT_NEAR(t2, t, 1e-5f);
            }
        }
    }
    // The first row of a side face is its top: up in the world.
    EXPECT_GT(cube_face_direction(0, 0.5f, 0.0f).y, 0.5f);
    EXPECT_GT(cube_face_direction(4, 0.5f, 0.0f).y, 0.5f);
}

TEST(Environment, MadeSkyTexelsAreSkyRadianceOfTheirDirection) {
    Renderer r(RenderSettings{64, 48});
    const SceneDesc scene = open_scene({0, 1.5f, 4}, {0, 0.8f, 0});
    r.set_scene(scene);
    const EnvironmentMap& env = r.environment();
    ASSERT_EQ(env.face_size(), kSkyFaceSize);
    const int n = env.face_size();
    const Vec3f sun = key_light(scene.camera);
    std::vector<std::uint8_t> texels(std::size_t(n) * n * 4u);
    int worst = 0;
    for (int face = 0; face < 6; ++face) {
        env.read_face(face, texels);
        for (int y = 0; y < n; y += 3) {
            for (int x = 0; x < n; x += 3) {
                const std::uint8_t* p = &texels[(std::size_t(y) * n + x) * 4u];
                const Vec3f d =
                    cube_face_direction(face, (float(x) + 0.5f) / float(n), (float(y) + 0.5f) / float(n));
                worst = std::max(worst, channel_error({p[0], p[1], p[2]}, sky_radiance(d, sun)));
            }
        }
    }
    EXPECT_LE(worst, 1) << "levels off sky_radiance";
    // The sky glows towards the key light, and below the horizon is the floor's bounce.
    EXPECT_LE(channel_error({140, 133, 120}, sky_radiance({0, -1, 0}, sun)), 1);
    EXPECT_GT(sky_radiance(normalize(Vec3f{sun.x, 0.3f, sun.z}), sun).x,
              sky_radiance(normalize(Vec3f{-sun.x, 0.3f, -sun.z}), sun).x);
}

TEST(Environment, BackgroundIsTheCubeMapInTheViewDirection) {
    Renderer r(RenderSettings{kW, kH});
    const SceneDesc scene = open_scene({0, 1, 0}, {1, 1.7f, 0.4f});  // looking up: only sky in view
    r.set_scene(scene);
    r.render(FrameView{});
    const Picture pic(r);
    const Vec3f sun = key_light(scene.camera);
    for (auto [x, y] : {std::pair{kW / 2, kH / 2}, std::pair{20, 30}, std::pair{kW - 15, kH - 20}}) {
        const Vec3f d = pixel_ray(scene.camera, x, y);
        EXPECT_LE(channel_error(pic.at(x, y), sky_radiance(d, sun)), 2) << x << "," << y;
    }
}

TEST(Environment, LoadedFacesShowBehindTheSceneAndInReflections) {
    const std::vector<std::string> faces = solid_faces("env_solid");
    Renderer r(RenderSettings{kW, kH});
    SceneDesc scene = open_scene({0, 1, 0}, {1, 1.2f, 0});
    scene.look.environment.faces = faces;
    // Look into each face (the side faces slightly upwards, over the ground plane): the centre pixel is
    // that face's colour.
    const Vec3f into[5] = {
        {1, 0.2f, 0.1f}, {-1, 0.2f, -0.1f}, {0.1f, 1, 0.2f}, {0.1f, 0.2f, 1}, {-0.1f, 0.2f, -1}};
    const int face_of[5] = {0, 1, 2, 4, 5};
    for (int i = 0; i < 5; ++i) {
        scene.camera.target = scene.camera.eye + into[i];
        r.set_scene(scene);
        r.render(FrameView{});
        keep_picture(r, std::string("loaded_face_") + (i == 0   ? "px"
                                                       : i == 1 ? "nx"
                                                       : i == 2 ? "py"
                                                       : i == 3 ? "pz"
                                                                : "nz"));
        const Picture pic(r);
        const Rgb want = kFaceColors[std::size_t(face_of[i])];
        const Rgb got = pic.at(kW / 2, kH / 2);
        EXPECT_LE(std::max({std::abs(got.r - want.r), std::abs(got.g - want.g), std::abs(got.b - want.b)}), 1)
            << "face " << cube_face_name(face_of[i]) << " got " << got.r << "," << got.g << "," << got.b;
    }

    // A water sphere reflects what surrounds it: with every face red its rim turns redder than with
    // every face green.
    const SphereMesh ball = sphere_mesh({0, 1, 0}, 0.5f);
    const auto rim_color = [&](Rgb c) {
        const std::string dir = "env_" + std::to_string(c.r) + "_" + std::to_string(c.g);
        std::vector<std::string> same(6);
        std::filesystem::create_directories(test::temp_path(dir));
        for (int f = 0; f < 6; ++f) {
            same[std::size_t(f)] = test::temp_path(dir + "/f" + std::to_string(f) + ".png");
            write_solid_png(same[std::size_t(f)], 8, 8, c);
        }
        SceneDesc s = open_scene({0, 1.2f, 3}, {0, 1, 0});
        s.look.environment.faces = same;
        r.set_scene(s);
        FrameView frame;
        frame.mesh = {ball.vertices, ball.indices};
        r.render(frame);
        keep_picture(r, "reflection_" + dir);
        const Picture pic(r);
        float px = 0, py = 0;
        EXPECT_TRUE(project_to_pixel(s.camera, kW, kH, {0.47f, 1.0f, 0.12f}, px, py));  // near the silhouette
        return pic.at(int(px), int(py));
    };
    const Rgb red = rim_color({230, 20, 20}), green = rim_color({20, 230, 20});
    EXPECT_GT(red.r, green.r + 25) << red.r << " vs " << green.r;
    EXPECT_GT(green.g, red.g + 25) << green.g << " vs " << red.g;
}

TEST(Environment, BadFacesAreErrorsNamingTheFile) {
    Renderer r(RenderSettings{64, 48});
    SceneDesc scene = open_scene({0, 1, 3}, {0, 1, 0});
    std::vector<std::string> faces = solid_faces("env_bad");
    const auto error_with = [&](const std::vector<std::string>& f) {
        scene.look.environment.faces = f;
        return error_of([&] { r.set_scene(scene); });
    };

    std::vector<std::string> missing = faces;
    missing[2] = test::temp_path("env_bad/absent.png");
    std::string e = error_with(missing);
    EXPECT_TRUE(Contains(e, "absent.png"));
    EXPECT_TRUE(Contains(e, "+y"));

    std::vector<std::string> not_png = faces;
    not_png[1] = test::temp_path("env_bad/text.png");
    test::write_text(not_png[1], "not a picture");
    e = error_with(not_png);
    EXPECT_TRUE(Contains(e, "text.png"));
    EXPECT_TRUE(Contains(e, "-x"));

    std::vector<std::string> oblong = faces;
    oblong[4] = test::temp_path("env_bad/oblong.png");
    write_solid_png(oblong[4], 16, 8, {1, 2, 3});
    e = error_with(oblong);
    EXPECT_TRUE(Contains(e, "oblong.png"));
    EXPECT_TRUE(Contains(e, "square"));
    EXPECT_TRUE(Contains(e, "16x8"));

    std::vector<std::string> smaller = faces;
    smaller[5] = test::temp_path("env_bad/small.png");
    write_solid_png(smaller[5], 8, 8, {1, 2, 3});
    e = error_with(smaller);
    EXPECT_TRUE(Contains(e, "small.png"));
    EXPECT_TRUE(Contains(e, "same size"));

    e = error_with(std::vector<std::string>(faces.begin(), faces.begin() + 5));
    EXPECT_TRUE(Contains(e, "six faces"));

    // After all that the renderer still draws with its last good environment.
    scene.look.environment.faces = faces;
    r.set_scene(scene);
    EXPECT_NO_THROW(r.render(FrameView{}));
}

// --- shadows ---

struct ShadowScene {
    SceneDesc scene = open_scene({0, 1.3f, 3.5f}, {0, 0.3f, 0});
    Vec3f center{0, 1.0f, 0};
    float radius = 0.25f;
};

// The shadow scene's renderer, its picture without fluid, and a water sphere's mesh.
struct SphereShadow {
    ShadowScene t;
    Renderer r{RenderSettings{kW, kH}};
    Picture empty = (r.set_scene(t.scene), r.render(FrameView{}), Picture(r));
    SphereMesh ball = sphere_mesh(t.center, t.radius);
    FrameView frame() const {
        FrameView f;
        f.mesh = {ball.vertices, ball.indices};
        return f;
    }
};

TEST(Shadows, AWaterSphereHalfDarkensTheGroundWhereTheLightSaysAndNowhereElse) {
    SphereShadow s;
    const ShadowScene& t = s.t;
    Renderer& r = s.r;
    const Picture& empty = s.empty;
    r.render(s.frame());
    keep_picture(r, "sphere_shadow");
    const Picture shaded(r);

    const Vec3f L = key_light(t.scene.camera);
    // The sphere's shadow on the ground is centred where the light's ray through its centre lands.
    const Vec3f g = t.center - L * (t.center.y / L.y);
    const Rgb lit = empty.at_world(t.scene.camera, g), dark = shaded.at_world(t.scene.camera, g);
    // Ground shading is albedo (0.45 + 0.55 n.l f), f the light reaching it: water lets half through.
    const float ratio = (0.45f + 0.55f * L.y * 0.5f) / (0.45f + 0.55f * L.y);
    EXPECT_NEAR(float(dark.sum()) / float(lit.sum()), ratio, 0.03f) << dark.sum() << " vs " << lit.sum();
    // Far from it the ground keeps its colour.
    const Vec3f far = g + Vec3f{0.9f, 0, 0.3f};
    EXPECT_EQ(shaded.at_world(t.scene.camera, far), empty.at_world(t.scene.camera, far));

    // Every pixel is the same bytes as without the sphere, except where the sphere itself is seen and
    // where its shadow can fall (the ground within a light ray's reach of the sphere, 3 cm to spare).
    int changed_outside = 0, checked = 0, darkened_inside = 0, inside = 0;
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            const Vec3f d = pixel_ray(t.scene.camera, x, y);
            if (ray_hits_sphere(t.scene.camera.eye, d, t.center, t.radius + 0.03f)) continue;
            bool shadow_possible = false, shadow_sure = false;
            if (d.y < 0) {
                const Vec3f p = t.scene.camera.eye + d * (-t.scene.camera.eye.y / d.y);
                shadow_possible = ray_hits_sphere(p, L, t.center, t.radius + 0.03f);
                shadow_sure = ray_hits_sphere(p, L, t.center, t.radius - 0.03f);
            }
            if (shadow_sure) {
                ++inside;
                darkened_inside += 10 * shaded.at(x, y).sum() < 9 * empty.at(x, y).sum();
            }
            if (shadow_possible) continue;
            ++checked;
            changed_outside += !(shaded.at(x, y) == empty.at(x, y));
        }
    }
    EXPECT_GT(checked, kW * kH / 2);
    EXPECT_EQ(changed_outside, 0);
    EXPECT_GT(inside, 100);
    EXPECT_EQ(darkened_inside, inside);
}

bool ray_hits_box(Vec3f o, Vec3f d, const BoxCollider& b) {
    float t0 = 0, t1 = 1e30f;
    const float os[3] = {o.x, o.y, o.z}, ds[3] = {d.x, d.y, d.z};
    const float lo[3] = {b.min.x, b.min.y, b.min.z}, hi[3] = {b.max.x, b.max.y, b.max.z};
    for (int a = 0; a < 3; ++a) {
        if (std::abs(ds[a]) < 1e-9f) {
            if (os[a] < lo[a] || os[a] > hi[a]) return false;
            continue;
        }
        float ta = (lo[a] - os[a]) / ds[a], tb = (hi[a] - os[a]) / ds[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    return t0 <= t1;
}

TEST(Shadows, ParticlesCastThemAsInstancedSpheresAndAsSprites) {
    ShadowScene t;
    t.radius = 0.08f;
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(t.scene);
    r.render(FrameView{});
    const Picture empty(r);
    const Vec3f L = key_light(t.scene.camera);
    const Vec3f g = t.center - L * (t.center.y / L.y);
    const float lit = float(empty.at_world(t.scene.camera, g).sum());
    const float ratio = (0.45f + 0.55f * L.y * 0.5f) / (0.45f + 0.55f * L.y);

    const float centre[3] = {t.center.x, t.center.y, t.center.z};
    FrameView spheres;  // scan conversion's isolated particles
    spheres.sphere_centers = centre;
    spheres.sphere_radius = t.radius;
    r.render(spheres);
    EXPECT_NEAR(float(Picture(r).at_world(t.scene.camera, g).sum()) / lit, ratio, 0.03f);

    FrameView sprites;  // the screen-space fluid's particles (drawn here by nothing but the shadow pass)
    sprites.sprites = {std::span(centre, 1), std::span(centre + 1, 1), std::span(centre + 2, 1)};
    sprites.sphere_radius = t.radius;
    r.render(sprites);
    const Picture shadowed(r);
    EXPECT_NEAR(float(shadowed.at_world(t.scene.camera, g).sum()) / lit, ratio, 0.03f);
    // Round, of the particle's radius: lit a radius and a half away across the light.
    const Vec3f across = normalize(cross(L, Vec3f{0, 1, 0}));
    EXPECT_EQ(shadowed.at_world(t.scene.camera, g + across * (1.5f * t.radius)),
              empty.at_world(t.scene.camera, g + across * (1.5f * t.radius)));
}

// Marching slices leaves its mesh out of the shadow pass and gives its particles instead
// (FrameView::mesh_casts_shadow): a drop's mesh, a sphere of the particle's radius around its centre,
// then casts the shadow its particle does, and with neither nothing darkens the ground.
TEST(Shadows, AMeshMayLeaveItsShadowToItsParticles) {
    SphereShadow sphere;
    const ShadowScene& t = sphere.t;
    sphere.r.render(sphere.frame());
    const Picture mesh_shadow(sphere.r), &empty = sphere.empty;

    FrameView unshadowed = sphere.frame();
    unshadowed.mesh_casts_shadow = false;
    sphere.r.render(unshadowed);
    const Picture none(sphere.r);
    const float centre[3] = {t.center.x, t.center.y, t.center.z};
    FrameView by_particle = unshadowed;
    by_particle.sprites = {std::span(centre, 1), std::span(centre + 1, 1), std::span(centre + 2, 1)};
    by_particle.sphere_radius = t.radius;
    sphere.r.render(by_particle);
    keep_picture(sphere.r, "particle_shadow");
    const Picture particle_shadow(sphere.r);

    const Vec3f L = key_light(t.scene.camera);
    const Vec3f g = t.center - L * (t.center.y / L.y);
    EXPECT_EQ(none.at_world(t.scene.camera, g), empty.at_world(t.scene.camera, g));
    EXPECT_LT(10 * mesh_shadow.at_world(t.scene.camera, g).sum(),
              9 * empty.at_world(t.scene.camera, g).sum());
    // Over the ground (the sphere's own pixels left out), the two shadows differ at most along their rim.
    int shadowed = 0, differ = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            if (ray_hits_sphere(t.scene.camera.eye, pixel_ray(t.scene.camera, x, y), t.center,
                                t.radius + 0.02f))
                continue;
            const Rgb a = mesh_shadow.at(x, y), b = particle_shadow.at(x, y);
            shadowed += !(a == empty.at(x, y));
            differ += std::abs(a.sum() - b.sum()) > 24;
        }
    EXPECT_GT(shadowed, 200);
    EXPECT_LT(differ, shadowed / 10) << differ << " of " << shadowed;
}

TEST(Shadows, FlatLitSurfacesHaveNoAcneAndContactShadowsStayAttached) {
    Renderer r(RenderSettings{kW, kH});
    SceneDesc scene = open_scene({-0.8f, 1.6f, 3.0f}, {0, 0.2f, 0});
    const BoxCollider box{{-0.3f, 0, -0.3f}, {0.3f, 0.4f, 0.3f}};
    scene.boxes.push_back(box);
    r.set_scene(scene);
    r.render(FrameView{});
    keep_picture(r, "box_shadow");
    const Picture pic(r);
    // The box's top (a caster lit by the light it casts from) and its front face, and a patch of
    // ground inside one checker cell: uniform, no speckles.
    const auto spread = [&](Vec3f centre, Vec3f a, Vec3f b) {
        int lo = 1000, hi = -1;
        for (int i = -10; i <= 10; ++i)
            for (int k = -10; k <= 10; ++k) {
                const int s =
                    pic.at_world(scene.camera, centre + a * (0.1f * float(i)) + b * (0.1f * float(k))).sum();
                lo = std::min(lo, s), hi = std::max(hi, s);
            }
        return hi - lo;
    };
    EXPECT_LE(spread({0, 0.4f, 0}, {0.25f, 0, 0}, {0, 0, 0.25f}), 3);
    EXPECT_LE(spread({0, 0.2f, 0.3f}, {0.25f, 0, 0}, {0, 0.15f, 0}), 3);
    EXPECT_LE(spread({0.75f, 0, 0.75f}, {0.2f, 0, 0}, {0, 0, 0.2f}), 3);  // cell [0.5, 1)²

    // The ground a few centimetres from the box's foot, where the light's ray meets the box: dark, with
    // no lit gap between the box and its shadow.
    SceneDesc no_box = scene;
    no_box.boxes.clear();
    Renderer r2(RenderSettings{kW, kH});
    r2.set_scene(no_box);
    r2.render(FrameView{});
    const Picture ground(r2);
    const Vec3f L = key_light(scene.camera);
    int checked = 0;
    for (float d : {0.015f, 0.03f, 0.05f}) {
        for (float z : {-0.25f, -0.15f, -0.05f, 0.05f, 0.15f}) {
            for (Vec3f foot : {Vec3f{box.min.x - d, 0, z}, Vec3f{z, 0, box.min.z - d}}) {
                const Vec3f to_foot = normalize(foot - scene.camera.eye);
                if (!ray_hits_box(foot + L * 1e-4f, L, box) || ray_hits_box(scene.camera.eye, to_foot, box))
                    continue;
                ++checked;
                EXPECT_LT(5 * pic.at_world(scene.camera, foot).sum(),
                          4 * ground.at_world(scene.camera, foot).sum())
                    << foot.x << "," << foot.z;
            }
        }
    }
    EXPECT_GE(checked, 3);
}

TEST(Shadows, TheMapCoversTheStageWithSquareTexels) {
    SceneDesc scene = make_builtin_scene("fountain");
    const std::vector<Vec3f> stage = shadow_stage(scene);
    const ShadowFit fit = fit_shadow(key_light(scene.camera), stage, kShadowMapSize, scene.ground_y);
    for (Vec3f p : stage) {
        const Eigen::Vector4f c = clip_of(fit.texture_matrix, p);
        for (int axis = 0; axis < 3; ++axis) {
            EXPECT_GE(c[axis], 0.0f);
            EXPECT_LE(c[axis], 1.0f);
        }
    }
    EXPECT_LT(fit.texel_world, 0.004f);  // a few millimetres: finer than a particle
    // The ground the map reaches holds the pool.
    EXPECT_LE(fit.ground.x0, scene.pool.x0);
    EXPECT_GE(fit.ground.x1, scene.pool.x0 + scene.pool.size_x);
}

// --- the SPH tank ---

// Corners of the tank frame's outer box.
BoxCollider frame_box(const SceneDesc& s) {
    const BoxCollider g = tank_glass_box(s);
    const float t = tank_frame_width(s);
    return {{g.min.x - t, g.min.y, g.min.z - t}, {g.max.x + t, g.max.y + t, g.max.z + t}};
}

// Twice the signed area: which side of a -> b the point p is on.
float side(float ax, float ay, float bx, float by, float px, float py) {
    return (bx - ax) * (py - ay) - (by - ay) * (px - ax);
}

TEST(Tank, DrawnOnlyOverTheTankAndItsShadowWithTheFrameOnItsEdges) {
    const SceneDesc tank = make_builtin_scene("dambreak");
    SceneDesc no_tank = tank;
    no_tank.simulation = SimulationKind::kStreams;
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(no_tank);
    r.render(FrameView{});
    const Picture without(r);
    r.set_scene(tank);
    r.render(FrameView{});
    keep_picture(r, "tank");
    const Picture with(r);

    // Where the tank and its shadow can be: the convex hull of the frame's corners and of those corners
    // slid along the light to the ground, projected into the picture.
    const BoxCollider f = frame_box(tank);
    const Vec3f L = key_light(tank.camera);
    std::vector<std::array<float, 2>> pts;
    for (int i = 0; i < 8; ++i) {
        const Vec3f c{i & 1 ? f.max.x : f.min.x, i & 2 ? f.max.y : f.min.y, i & 4 ? f.max.z : f.min.z};
        for (Vec3f p : {c, c - L * ((c.y - tank.ground_y) / L.y)}) {
            float px = 0, py = 0;
            ASSERT_TRUE(project_to_pixel(tank.camera, kW, kH, p, px, py));
            pts.push_back({px, py});
        }
    }
    // Gift wrapping: the hull counter-clockwise in picture coordinates.
    std::sort(pts.begin(), pts.end());
    std::vector<std::array<float, 2>> hull;
    for (int pass = 0; pass < 2; ++pass) {
        const std::size_t start = hull.size();
        for (const auto& p : pts) {
            while (hull.size() >= start + 2 && side(hull[hull.size() - 2][0], hull[hull.size() - 2][1],
                                                    hull.back()[0], hull.back()[1], p[0], p[1]) <= 0)
                hull.pop_back();
            hull.push_back(p);
        }
        hull.pop_back();
        std::reverse(pts.begin(), pts.end());
    }
    const auto distance_outside = [&](float x, float y) {
        float worst = -1e9f;
        for (std::size_t i = 0; i < hull.size(); ++i) {
            const auto& a = hull[i];
            const auto& b = hull[(i + 1) % hull.size()];
            const float len = std::hypot(b[0] - a[0], b[1] - a[1]);
            worst = std::max(worst, -side(a[0], a[1], b[0], b[1], x, y) / len);
        }
        return worst;  // > 0 outside
    };
    int changed_outside = 0, changed = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const Rgb a = with.at(x, y), b = without.at(x, y);
            if (a == b) continue;
            ++changed;
            if (distance_outside(float(x) + 0.5f, float(y) + 0.5f) > 2.0f) ++changed_outside;
        }
    EXPECT_GT(changed, kW * kH / 20);
    EXPECT_EQ(changed_outside, 0);

    // The frame's beams lie where the box's edges project: dark metal along the top edges and the
    // front verticals, in front of the pale floor.
    const float t = tank_frame_width(tank), top = f.max.y - 0.5f * t;
    const float x0 = f.min.x + 0.5f * t, x1 = f.max.x - 0.5f * t, z0 = f.min.z + 0.5f * t,
                z1 = f.max.z - 0.5f * t;
    std::vector<Vec3f> beams;
    for (float u : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
        beams.push_back({x0 + (x1 - x0) * u, top, z1});                // front top edge
        beams.push_back({x0 + (x1 - x0) * u, top, z0});                // back top edge
        beams.push_back({x0, top, z0 + (z1 - z0) * u});                // left top edge
        beams.push_back({x1, top, z0 + (z1 - z0) * u});                // right top edge
        beams.push_back({x1, f.min.y + (f.max.y - f.min.y) * u, z1});  // front right vertical
    }
    for (Vec3f p : beams) {
        const Rgb c = with.at_world(tank.camera, p);
        EXPECT_LT(c.sum(), 3 * 110) << p.x << "," << p.y << "," << p.z;
        EXPECT_LT(c.sum(), without.at_world(tank.camera, p).sum() - 150) << p.x << "," << p.y << "," << p.z;
    }
    // The front glass tints what is behind it only faintly: the water must stay visible through it.
    const BoxCollider g = tank_glass_box(tank);
    const Vec3f front_middle{0.5f * (g.min.x + g.max.x), 0.5f * (g.min.y + g.max.y), g.max.z};
    const Rgb through = with.at_world(tank.camera, front_middle),
              bare = without.at_world(tank.camera, front_middle);
    EXPECT_NE(through, bare);
    EXPECT_LT(std::abs(through.sum() - bare.sum()), 3 * 30);
}

TEST(Tank, FollowsTheContainerOffset) {
    const SceneDesc tank = make_builtin_scene("dambreak");
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(tank);
    const BoxCollider f = frame_box(tank);
    const float t = tank_frame_width(tank);
    const Vec3f corner{f.min.x + 0.5f * t, f.max.y - 0.5f * t, f.max.z - 0.5f * t};  // top front left
    const Vec3f offset{0.15f, 0, 0};
    r.render(FrameView{});
    const Picture rest(r);
    r.set_container_offset(offset);
    r.render(FrameView{});
    const Picture moved(r);
    EXPECT_LT(rest.at_world(tank.camera, corner).sum(), 3 * 110);
    EXPECT_LT(moved.at_world(tank.camera, corner + offset).sum(), 3 * 110);
    EXPECT_GT(moved.at_world(tank.camera, corner).sum(), 3 * 110);  // the beam moved away from here
}

TEST(Tank, TheFluidIsClippedToTheGlass) {
    const SceneDesc tank = make_builtin_scene("dambreak");
    const BoxCollider g = tank_glass_box(tank);
    // A slab of water at mid height reaching well past the tank on both sides in x: clipped to the
    // glass, it still absorbs over its whole closed surface's thickness.
    const float y = 0.5f * (g.min.y + g.max.y), x0 = g.min.x - 0.6f, x1 = g.max.x + 0.6f;
    const test::BoxMesh slab = test::box_mesh({x0, y - 0.1f, g.min.z}, {x1, y, g.max.z});
    Renderer r(RenderSettings{kW, kH});
    r.set_scene(tank);
    FrameView frame;
    frame.mesh = {slab.vertices, slab.indices};
    r.render(frame);
    keep_picture(r, "tank_clip");
    const Picture pic(r);
    const auto blue = [](Rgb c) { return c.b > c.r + 40; };
    const float zm = 0.5f * (g.min.z + g.max.z);
    EXPECT_TRUE(blue(pic.at_world(tank.camera, {0.5f * (g.min.x + g.max.x), y, zm})));
    EXPECT_TRUE(blue(pic.at_world(tank.camera, {g.max.x - 0.03f, y, zm})));
    EXPECT_FALSE(blue(pic.at_world(tank.camera, {g.max.x + 0.08f, y, zm})));
    EXPECT_FALSE(blue(pic.at_world(tank.camera, {g.min.x - 0.08f, y, zm})));
}

// --- scene files ---

std::string scene_error(const std::string& text) {
    return error_of([&] { scene_from_json(nlohmann::json::parse(text), "look.json"); });
}

TEST(SceneLookJson, ParsesRoundTripsAndResolvesFacesNextToTheFile) {
    const std::vector<std::string> faces = solid_faces("look_scene");
    const std::string dir = std::filesystem::path(faces[0]).parent_path().string();
    const std::string path = dir + "/scene.json";
    test::write_text(path, R"({"base": "fountain", "look": {"water_color": [0.1, 0.2, 0.3],
        "absorption": [4, 2, 1], "environment": ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"]}})");
    const SceneDesc s = load_scene_file(path);
    EXPECT_EQ(s.look.water.color, (Vec3f{0.1f, 0.2f, 0.3f}));
    EXPECT_EQ(s.look.water.absorption, (Vec3f{4, 2, 1}));
    ASSERT_EQ(s.look.environment.faces.size(), 6u);
    for (std::size_t i = 0; i < 6; ++i)
        EXPECT_TRUE(std::filesystem::equivalent(s.look.environment.faces[i], faces[i]))
            << s.look.environment.faces[i];

    const nlohmann::json j = scene_to_json(s);
    EXPECT_EQ(j.at("look").at("environment").size(), 6u);
    const SceneDesc back = scene_from_json(j, "round trip");
    EXPECT_EQ(scene_to_json(back), j);
    EXPECT_EQ(back.look.water.color, s.look.water.color);
    EXPECT_EQ(back.look.water.absorption, s.look.water.absorption);
    EXPECT_EQ(back.look.environment.faces, s.look.environment.faces);
    // Left out, the look is the default: the made sky and the usual water.
    const SceneDesc plain = scene_from_json(nlohmann::json::parse(R"({"base": "fountain"})"), "plain");
    EXPECT_TRUE(plain.look.environment.faces.empty());
    EXPECT_EQ(plain.look.water.color, WaterLook{}.color);
}

TEST(SceneLookJson, BadValuesNameTheFieldOrFile) {
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"water_color": [0.1, 2.0, 0.3]}})"), "look.water_color"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"water_color": [0.1, 2.0, 0.3]}})"), "[0, 1]"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"absorption": [1, 2, 5000]}})"), "look.absorption"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"absorption": [-1, 2, 3]}})"), "look.absorption"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"environment": ["a", "b", "c", "d", "e"]}})"),
                         "look.environment needs six face images"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"environment": ["a", "b", "", "d", "e", "f"]}})"),
                         "look.environment[2]"));
    EXPECT_TRUE(
        Contains(scene_error(R"({"look": {"enviroment": []}})"), "look.json.look.enviroment: unknown key"));
    EXPECT_TRUE(Contains(scene_error(R"({"look": {"water_color": "blue"}})"), "look.json.look.water_color"));

    std::vector<std::string> faces = solid_faces("look_missing");
    const std::string dir = std::filesystem::path(faces[0]).parent_path().string();
    test::write_text(dir + "/scene.json", R"({"look": {"environment":
        ["px.png", "nx.png", "py.png", "gone.png", "pz.png", "nz.png"]}})");
    const std::string e = error_of([&] { load_scene_file(dir + "/scene.json"); });
    EXPECT_TRUE(Contains(e, "look.environment[3]"));
    EXPECT_TRUE(Contains(e, "gone.png"));
}

TEST(SceneLookCli, ABadFaceImageIsOneErrorLineAndExitOne) {
    std::vector<std::string> faces = solid_faces("look_cli");
    const std::string dir = std::filesystem::path(faces[0]).parent_path().string();
    write_solid_png(dir + "/pz.png", 16, 12, {9, 9, 9});  // not square
    test::write_text(dir + "/scene.json", R"({"base": "fountain", "warmup_frames": 0, "look": {"environment":
        ["px.png", "nx.png", "py.png", "ny.png", "pz.png", "nz.png"]}})");
    const test::Result r =
        test::run_cli("run --scene " + dir + "/scene.json --frames 1 --size 64x48 --out ''");
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_TRUE(Contains(r.output, "rivulet: error: "));
    EXPECT_TRUE(Contains(r.output, "pz.png"));
    EXPECT_TRUE(Contains(r.output, "square"));
}

}  // namespace
}  // namespace rivulet
