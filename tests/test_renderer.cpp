// Renderer, camera, PNG writer and the particle sphere template, checked on real pixels.
#include <gtest/gtest.h>
#include <png.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "jobs/cylinder_layout.h"
#include "jobs/low_res_sphere.h"
#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/png_writer.h"
#include "systems/render/renderer.h"

namespace rivulet {
namespace {

constexpr int kW = 320, kH = 240;

struct Rgb {
    int r, g, b;
};

bool water_blue(Rgb c) {
    return c.b > c.r + 40 && c.b > 90;
}

class Picture {
  public:
    explicit Picture(const Renderer& r) : w_(r.width()), rgba_(std::size_t(r.width()) * r.height() * 4u) {
        r.read_rgba(rgba_);
    }
    Rgb at(int x, int y) const {
        const std::uint8_t* p = &rgba_[(std::size_t(y) * w_ + x) * 4u];
        return {p[0], p[1], p[2]};
    }
    // The pixel where `world` lands; fails the test if it is off screen.
    Rgb at_world(const CameraDesc& cam, Vec3f world) const {
        float px = 0, py = 0;
        EXPECT_TRUE(project_to_pixel(cam, kW, kH, world, px, py));
        return at(static_cast<int>(px), static_cast<int>(py));
    }
    const std::vector<std::uint8_t>& rgba() const { return rgba_; }

  private:
    int w_;
    std::vector<std::uint8_t> rgba_;
};

::testing::AssertionResult IsWater(Rgb c) {
    if (water_blue(c)) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure()
           << "rgb(" << c.r << ", " << c.g << ", " << c.b << ") is not water-blue";
}

SceneDesc scene_with_camera(Vec3f eye, Vec3f target) {
    SceneDesc s;
    s.camera.eye = eye;
    s.camera.target = target;
    s.camera.fov_y_deg = 45;
    return s;
}

// Cylinder 0 as a vertical tube of radius 0.3 around the y axis, rings 2..7 valid.
std::vector<float> tube_vertices(const CylinderLayout& l) {
    std::vector<float> v(std::size_t(l.verts_per_cylinder()) * 6u, 0.0f);
    auto put = [&](std::uint32_t i, Vec3f p, Vec3f n) {
        float* o = &v[std::size_t(i) * 6u];
        o[0] = p.x, o[1] = p.y, o[2] = p.z, o[3] = n.x, o[4] = n.y, o[5] = n.z;
    };
    for (std::uint32_t r = 2; r <= 7; ++r) {
        const float y = 2.0f - 0.15f * static_cast<float>(r);
        for (std::uint32_t k = 0; k < l.u; ++k) {
            const float a = 2 * std::numbers::pi_v<float> * static_cast<float>(k) / static_cast<float>(l.u);
            const Vec3f n{std::cos(a), 0, std::sin(a)};
            put(l.side_vertex(r, k), Vec3f{0, y, 0} + n * 0.3f, n);
        }
        put(l.top_pole(r), {0, y + 0.05f, 0}, {0, 1, 0});
        put(l.bottom_pole(r), {0, y - 0.05f, 0}, {0, -1, 0});
    }
    return v;
}

TEST(Renderer, CreatesCoreContext) {
    Renderer r(RenderSettings{kW, kH});
    EXPECT_NE(r.gl_version().find("4.5"), std::string::npos) << r.gl_version();
    EXPECT_FALSE(r.gl_renderer().empty());
    EXPECT_EQ(r.width(), kW);
    EXPECT_EQ(r.height(), kH);
}

TEST(Renderer, RejectsBadSizes) {
    EXPECT_THROW(Renderer(RenderSettings{8, 240}), std::runtime_error);
    EXPECT_THROW(Renderer(RenderSettings{320, 9000}), std::runtime_error);
}

TEST(Renderer, DrawsCylinderGroupFromPool) {
    Renderer r(RenderSettings{kW, kH});
    const SceneDesc scene = scene_with_camera({0, 1.3f, 2.5f}, {0, 1.3f, 0});
    r.set_scene(scene);
    const CylinderLayout layout{16, 10};
    r.set_cylinder_pool(layout, 4);
    const std::vector<float> verts = tube_vertices(layout);
    std::vector<float> pool_verts(std::size_t(layout.verts_per_cylinder()) * 4u * 6u, 0.0f);
    std::copy(verts.begin(), verts.end(), pool_verts.begin());
    const GroupDraw groups[] = {{0, 2, 7}};
    FrameView frame;
    frame.cylinders = {pool_verts, groups};
    r.render(frame);
    const Picture pic(r);
    EXPECT_TRUE(IsWater(pic.at_world(scene.camera, {0, 1.3f, 0})));
    EXPECT_TRUE(IsWater(pic.at_world(scene.camera, {0, 1.65f, 0})));  // near the top cap
    EXPECT_FALSE(water_blue(pic.at_world(scene.camera, {1.2f, 1.3f, 0})));
    EXPECT_FALSE(water_blue(pic.at(10, kH - 10)));  // ground
    EXPECT_FALSE(water_blue(pic.at(10, 10)));       // sky
    // Above ring 2's cap nothing was drawn.
    EXPECT_FALSE(water_blue(pic.at_world(scene.camera, {0, 1.85f, 0})));

    const GroupDraw out_of_range[] = {{0, 2, 10}};
    frame.cylinders = {pool_verts, out_of_range};
    EXPECT_THROW(r.render(frame), std::out_of_range);
}

TEST(Renderer, DrawsInstancedSpheres) {
    Renderer r(RenderSettings{kW, kH});
    const SceneDesc scene = scene_with_camera({0, 1, 3}, {0, 1, 0});
    r.set_scene(scene);
    const Vec3f centers[] = {{0, 1, 0}, {-0.8f, 1.2f, 0}};
    FrameView frame;
    r.render(frame);
    const Picture empty(r);
    EXPECT_FALSE(water_blue(empty.at_world(scene.camera, centers[0])));

    const float xyz[] = {centers[0].x, centers[0].y, centers[0].z, centers[1].x, centers[1].y, centers[1].z};
    frame.sphere_centers = xyz;
    frame.sphere_radius = 0.15f;
    r.render(frame);
    const Picture drawn(r);
    EXPECT_TRUE(IsWater(drawn.at_world(scene.camera, centers[0])));
    EXPECT_TRUE(IsWater(drawn.at_world(scene.camera, centers[1])));
    EXPECT_FALSE(water_blue(drawn.at_world(scene.camera, {0.8f, 1, 0})));
}

TEST(Renderer, DrawsPoolHeightField) {
    Renderer r(RenderSettings{kW, kH});
    SceneDesc scene = scene_with_camera({0, 2.5f, 3}, {0, 0, 0});
    scene.pool.enabled = true;
    scene.pool.x0 = -1, scene.pool.z0 = -1, scene.pool.size_x = 2, scene.pool.size_z = 2;
    scene.pool.nx = 32, scene.pool.nz = 24;
    scene.pool.level = 0.1f;
    r.set_scene(scene);
    std::vector<float> heights(32 * 24, 0.1f);
    FrameView frame;
    frame.pool = {32, 24, -1, -1, 2.0f / 31, 2.0f / 23, heights};
    r.render(frame);
    const Picture pic(r);
    EXPECT_TRUE(IsWater(pic.at_world(scene.camera, {0, 0.1f, 0})));
    EXPECT_TRUE(IsWater(pic.at_world(scene.camera, {-0.8f, 0.1f, 0.8f})));
    EXPECT_FALSE(water_blue(pic.at_world(scene.camera, {1.8f, 0, 0.5f})));
    EXPECT_FALSE(water_blue(pic.at_world(scene.camera, {0, 0, -2.0f})));

    heights.resize(10);
    frame.pool.heights = heights;
    EXPECT_THROW(r.render(frame), std::out_of_range);
}

TEST(Renderer, DrawsMeshAndColliders) {
    Renderer r(RenderSettings{kW, kH});
    SceneDesc scene = scene_with_camera({0, 1, 3}, {0, 0.5f, 0});
    scene.spheres.push_back({{-0.8f, 0.4f, 0}, 0.4f});
    scene.boxes.push_back({{0.5f, 0, -0.3f}, {1.1f, 0.6f, 0.3f}});
    r.set_scene(scene);
    // A closed slab of water as a generic mesh: the water absorbs over its thickness.
    const test::BoxMesh slab = test::box_mesh({-0.3f, 0.7f, -0.3f}, {0.3f, 0.9f, 0.3f});
    FrameView frame;
    frame.mesh = {slab.vertices, slab.indices};
    r.render(frame);
    const Picture pic(r);
    // Its face towards the camera (the top is seen at grazing angles and mirrors the sky).
    EXPECT_TRUE(IsWater(pic.at_world(scene.camera, {0, 0.8f, 0.3f})));
    const Rgb sphere = pic.at_world(scene.camera, {-0.8f, 0.4f, 0.4f});
    const Rgb box = pic.at_world(scene.camera, {0.8f, 0.3f, 0.3f});
    for (Rgb c : {sphere, box}) {
        EXPECT_FALSE(water_blue(c));
        EXPECT_LT(std::abs(c.r - c.b), 30) << "colliders are grey";
    }
}

TEST(Renderer, SceneSnapshotRoundTripsThroughPng) {
    Renderer r(RenderSettings{kW, kH});
    SceneDesc scene = scene_with_camera({0.5f, 1.8f, 3.2f}, {0, 0.6f, 0});
    scene.pool.enabled = true;
    scene.pool.x0 = -1.2f, scene.pool.z0 = -0.8f, scene.pool.size_x = 2.4f, scene.pool.size_z = 1.6f;
    scene.pool.nx = 64, scene.pool.nz = 48;
    scene.pool.level = 0.15f;
    scene.spheres.push_back({{1.6f, 0.3f, -0.6f}, 0.3f});
    r.set_scene(scene);
    const CylinderLayout layout{16, 10};
    r.set_cylinder_pool(layout, 1);
    const std::vector<float> verts = tube_vertices(layout);
    const GroupDraw groups[] = {{0, 2, 7}};
    std::vector<float> heights(64 * 48);
    const float dx = 2.4f / 63, dz = 1.6f / 47;
    for (int iz = 0; iz < 48; ++iz) {
        for (int ix = 0; ix < 64; ++ix) {
            const float x = -1.2f + static_cast<float>(ix) * dx, z = -0.8f + static_cast<float>(iz) * dz;
            heights[iz * 64 + ix] = 0.15f + 0.03f * std::cos(9 * std::sqrt(x * x + z * z));
        }
    }
    std::vector<float> drops;
    for (int i = 0; i < 12; ++i)
        drops.insert(drops.end(),
                     {0.4f + 0.08f * static_cast<float>(i), 0.5f + 0.06f * static_cast<float>(i), 0.1f});
    FrameView frame;
    frame.cylinders = {verts, groups};
    frame.pool = {64, 48, -1.2f, -0.8f, dx, dz, heights};
    frame.sphere_centers = drops;
    frame.sphere_radius = 0.04f;
    r.render(frame);
    const Picture pic(r);

    const std::string path = test::temp_path("renderer_snapshot.png");
    write_png_rgba(path, kW, kH, pic.rgba());
    png_image image{};
    image.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
    image.format = PNG_FORMAT_RGBA;
    ASSERT_EQ(image.width, unsigned(kW));
    ASSERT_EQ(image.height, unsigned(kH));
    std::vector<std::uint8_t> back(PNG_IMAGE_SIZE(image));
    ASSERT_TRUE(png_image_finish_read(&image, nullptr, back.data(), 0, nullptr)) << image.message;
    EXPECT_EQ(back, pic.rgba());  // rendered pixels are opaque, so dropping alpha loses nothing
}

TEST(PngWriter, RoundTripsSmallPicture) {
    constexpr int w = 7, h = 5;
    std::vector<std::uint8_t> rgba(w * h * 4);
    for (int i = 0; i < w * h; ++i) {
        rgba[4 * i] = static_cast<std::uint8_t>(i * 7);
        rgba[4 * i + 1] = static_cast<std::uint8_t>(255 - i * 3);
        rgba[4 * i + 2] = static_cast<std::uint8_t>(i * i);
        rgba[4 * i + 3] = 255;
    }
    for (int level : {0, 1, 9}) {
        const std::string path = test::temp_path("small_" + std::to_string(level) + ".png");
        write_png_rgba(path, w, h, rgba, level);
        png_image image{};
        image.version = PNG_IMAGE_VERSION;
        ASSERT_TRUE(png_image_begin_read_from_file(&image, path.c_str())) << image.message;
        image.format = PNG_FORMAT_RGBA;
        std::vector<std::uint8_t> back(PNG_IMAGE_SIZE(image));
        ASSERT_TRUE(png_image_finish_read(&image, nullptr, back.data(), 0, nullptr)) << image.message;
        EXPECT_EQ(back, rgba);
    }
}

TEST(PngWriter, ReportsUnwritablePath) {
    const std::vector<std::uint8_t> rgba(16 * 16 * 4, 255);
    try {
        write_png_rgba("/nonexistent-dir/x.png", 16, 16, rgba);
        FAIL() << "expected an exception";
    } catch (const std::runtime_error& e) {
        EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.png"), std::string::npos) << e.what();
    }
}

TEST(Camera, ProjectsTargetToPictureCentre) {
    CameraDesc cam;
    cam.eye = {1, 2, 5};
    cam.target = {0.5f, 0.7f, -1};
    float px = 0, py = 0;
    ASSERT_TRUE(project_to_pixel(cam, 640, 360, cam.target, px, py));
    EXPECT_NEAR(px, 320, 1e-2);
    EXPECT_NEAR(py, 180, 1e-2);
    // Up in the world is up in the picture (smaller py); behind the camera does not project.
    ASSERT_TRUE(project_to_pixel(cam, 640, 360, cam.target + Vec3f{0, 0.5f, 0}, px, py));
    EXPECT_LT(py, 180);
    EXPECT_FALSE(project_to_pixel(cam, 640, 360, cam.eye * 2.0f - cam.target, px, py));
}

TEST(LowResSphere, IsClosedOutwardUnitIcosphere) {
    const SphereTemplate& s = low_res_sphere();
    ASSERT_EQ(s.positions.size(), 42u * 3u);
    ASSERT_EQ(s.indices.size(), 80u * 3u);
    EXPECT_EQ(test::count_open_edges(s.positions, s.indices, 0.0f), 0u);
    auto p = [&](std::uint32_t i) {
        return Vec3f{s.positions[3 * i], s.positions[3 * i + 1], s.positions[3 * i + 2]};
    };
    for (std::uint32_t i = 0; i < 42; ++i) EXPECT_NEAR(length(p(i)), 1.0f, 1e-5f);
    for (std::size_t t = 0; t < s.indices.size(); t += 3) {
        const Vec3f a = p(s.indices[t]), b = p(s.indices[t + 1]), c = p(s.indices[t + 2]);
        EXPECT_GT(dot(cross(b - a, c - a), a + b + c), 0.0f) << "triangle " << t / 3;
    }
    EXPECT_EQ(&low_res_sphere(), &s);
}

}  // namespace
}  // namespace rivulet
