// Diffuse objects' sprite pass, checked on real pixels: soft round point sprites sized in world units,
// blended in the order given ("over") or added, tested against the scene's depth.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <vector>

#include "support/test_support.h"
#include "systems/render/camera.h"
#include "systems/render/renderer.h"

namespace rivulet {
namespace {

constexpr int kW = 160, kH = 120;

struct Rgb {
    int r, g, b;
};

std::uint32_t pack(int r, int g, int b, int a) {
    return std::uint32_t(r) | std::uint32_t(g) << 8 | std::uint32_t(b) << 16 | std::uint32_t(a) << 24;
}

class Picture {
  public:
    explicit Picture(const Renderer& r) : rgba_(std::size_t(kW) * kH * 4u) { r.read_rgba(rgba_); }
    Rgb at(int x, int y) const {
        const std::uint8_t* p = &rgba_[(std::size_t(y) * kW + x) * 4u];
        return {p[0], p[1], p[2]};
    }
    bool same_at(const Picture& o, int x, int y) const {
        const Rgb a = at(x, y), b = o.at(x, y);
        return a.r == b.r && a.g == b.g && a.b == b.b;
    }

  private:
    std::vector<std::uint8_t> rgba_;
};

// One renderer for the whole file: making the context and its programs is most of a test's time.
class DiffuseSprites : public ::testing::Test {
  protected:
    static void SetUpTestSuite() {
        renderer_ = std::make_unique<Renderer>(RenderSettings{kW, kH});
        renderer_->set_scene(test::facing_scene());
        renderer_->set_diffuse_sprites(16);
    }
    static void TearDownTestSuite() { renderer_.reset(); }

    static Picture draw(std::span<const DiffuseSprite> sprites, bool additive = false,
                        const TriangleMeshView& mesh = {}, std::span<const std::uint32_t> order = {}) {
        FrameView frame;
        frame.mesh = mesh;
        frame.diffuse = {sprites, order, additive};
        renderer_->render(frame);
        return Picture(*renderer_);
    }

    // Where a world point lands, as a pixel (column, row from the top).
    static void pixel_of(Vec3f world, int& x, int& y) {
        float px = 0, py = 0;
        ASSERT_TRUE(project_to_pixel(test::facing_scene().camera, kW, kH, world, px, py));
        x = static_cast<int>(px), y = static_cast<int>(py);
    }

    // Pixels of row `y` that differ from `background`: the sprite's width there.
    static int changed_in_row(const Picture& p, const Picture& background, int y) {
        int n = 0;
        for (int x = 0; x < kW; ++x) n += p.same_at(background, x, y) ? 0 : 1;
        return n;
    }

    static std::unique_ptr<Renderer> renderer_;
};

std::unique_ptr<Renderer> DiffuseSprites::renderer_;

// The camera sits at z = 3 looking at (0, 0.5, 0), 40 degrees high: 0.5 * 120 / tan(20 deg) = 164.8
// pixels per world unit at distance 1.
constexpr float kPixelsPerUnit = 164.8f;

TEST_F(DiffuseSprites, OneSpriteTakesItsColourInsideAndLeavesTheRestAlone) {
    const Picture background = draw({});
    const DiffuseSprite sprite{0, 0.5f, 0, 0.6f, pack(255, 0, 0, 255)};
    const Picture p = draw(std::span(&sprite, 1));
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    const Rgb c = p.at(cx, cy);
    EXPECT_GE(c.r, 245);
    EXPECT_LE(c.g, 12);
    EXPECT_LE(c.b, 12);
    const float radius = 0.5f * 0.6f * kPixelsPerUnit / 3.0f;  // 16.5 px
    int outside = 0, changed = 0;
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            const float d = std::hypot(float(x) + 0.5f - float(cx), float(y) + 0.5f - float(cy));
            if (d < radius + 1.5f) continue;
            ++outside;
            changed += p.same_at(background, x, y) ? 0 : 1;
        }
    }
    EXPECT_GT(outside, kW * kH / 2);
    EXPECT_EQ(changed, 0) << "pixels changed outside the sprite's radius of " << radius;
    // And inside it, the disc is there: most of its row is covered.
    EXPECT_GT(changed_in_row(p, background, cy), int(1.5f * radius));
}

// A dead particle's sprite stays in the frame's array with alpha zero: it must leave every pixel alone.
TEST_F(DiffuseSprites, ATransparentSpriteChangesNoPixel) {
    const Picture background = draw({});
    const DiffuseSprite sprites[] = {{0, 0.5f, 0, 0.6f, pack(255, 0, 0, 0)},
                                     {0.1f, 0.4f, 0.2f, 0.3f, pack(255, 255, 255, 0)}};
    for (const bool additive : {false, true}) {
        const Picture p = draw(sprites, additive);
        int changed = 0;
        for (int y = 0; y < kH; ++y)
            for (int x = 0; x < kW; ++x) changed += p.same_at(background, x, y) ? 0 : 1;
        EXPECT_EQ(changed, 0) << (additive ? "additive" : "over");
    }
}

TEST_F(DiffuseSprites, SizeOnScreenFollowsDistance) {
    const Picture background = draw({});
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    const DiffuseSprite near{0, 0.5f, 0, 1.0f, pack(20, 40, 200, 255)};  // 3 units away
    const DiffuseSprite far{0, 0.5f, -3, 1.0f, pack(20, 40, 200, 255)};  // 6 units away
    const int near_width = changed_in_row(draw(std::span(&near, 1)), background, cy);
    const int far_width = changed_in_row(draw(std::span(&far, 1)), background, cy);
    EXPECT_NEAR(float(near_width), kPixelsPerUnit / 3.0f, 4.0f);
    const float ratio = float(near_width) / float(far_width);
    EXPECT_NEAR(ratio, 2.0f, 0.25f) << near_width << " vs " << far_width << " pixels";
}

// Drawn in the order given, without depth writes: back to front shows the nearer one on top, and the
// reverse order would show the farther one (so the order, not a depth test, decides).
TEST_F(DiffuseSprites, OverBlendingShowsTheLastDrawnOnTop) {
    const DiffuseSprite far{0, 0.5f, -1.0f, 0.8f, pack(230, 20, 20, 240)};
    const DiffuseSprite near{0, 0.5f, 0.5f, 0.4f, pack(20, 230, 20, 240)};
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    const DiffuseSprite back_to_front[] = {far, near};
    const Rgb c = draw(back_to_front).at(cx, cy);
    EXPECT_GT(c.g, 180);
    EXPECT_LT(c.r, 60);
    const DiffuseSprite front_to_back[] = {near, far};
    const Rgb wrong = draw(front_to_back).at(cx, cy);
    EXPECT_GT(wrong.r, 180);
    EXPECT_LT(wrong.g, 60);
}

// With an order the sprites are drawn through it, not as they lie: the same array shows the near one on
// top when the order puts it last, and the far one when the order puts that last.
TEST_F(DiffuseSprites, AnOrderDecidesWhichIsDrawnLast) {
    const DiffuseSprite sprites[] = {
        {0, 0.5f, 0.5f, 0.4f, pack(20, 230, 20, 240)},   // near, green
        {0, 0.5f, -1.0f, 0.8f, pack(230, 20, 20, 240)},  // far, red
    };
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    const std::uint32_t back_to_front[] = {1, 0}, front_to_back[] = {0, 1};
    const Rgb c = draw(sprites, false, {}, back_to_front).at(cx, cy);
    EXPECT_GT(c.g, 180);
    EXPECT_LT(c.r, 60);
    const Rgb wrong = draw(sprites, false, {}, front_to_back).at(cx, cy);
    EXPECT_GT(wrong.r, 180);
    EXPECT_LT(wrong.g, 60);
    const std::uint32_t short_order[] = {0};
    EXPECT_THROW(draw(sprites, false, {}, short_order), std::exception) << "an order must cover every sprite";
}

TEST_F(DiffuseSprites, AdditiveOverlapIsBrighterThanEither) {
    // Dim colours, so the sky behind plus both stays below saturation.
    const DiffuseSprite a{-0.1f, 0.5f, 0, 0.6f, pack(12, 12, 6, 255)};
    const DiffuseSprite b{0.1f, 0.5f, 0, 0.6f, pack(12, 12, 6, 255)};
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    const Rgb only_a = draw(std::span(&a, 1), true).at(cx, cy);
    const Rgb only_b = draw(std::span(&b, 1), true).at(cx, cy);
    const DiffuseSprite both[] = {a, b};
    const Rgb sum = draw(both, true).at(cx, cy);
    const Rgb sky = draw({}).at(cx, cy);
    ASSERT_LT(sky.r, 240);
    EXPECT_GT(only_a.r, sky.r);
    EXPECT_GT(sum.r, std::max(only_a.r, only_b.r));
    EXPECT_GT(sum.g, std::max(only_a.g, only_b.g));
    // Order-free: the reverse order gives the same picture.
    const DiffuseSprite reversed[] = {b, a};
    const Rgb again = draw(reversed, true).at(cx, cy);
    EXPECT_EQ(again.r, sum.r);
    EXPECT_EQ(again.g, sum.g);
}

// Depth-tested against the scene: a sprite behind an opaque surface leaves it as it was.
TEST_F(DiffuseSprites, HiddenBehindSceneGeometry) {
    const test::BoxMesh box = test::box_mesh({-0.5f, 0.0f, 0.8f}, {0.5f, 1.0f, 1.2f});
    const TriangleMeshView mesh{box.vertices, box.indices};
    const Picture without = draw({}, false, mesh);
    const DiffuseSprite behind{0, 0.5f, 0, 0.4f, pack(255, 0, 255, 255)};
    const Picture with = draw(std::span(&behind, 1), false, mesh);
    int cx = 0, cy = 0;
    pixel_of({0, 0.5f, 0}, cx, cy);
    EXPECT_TRUE(with.same_at(without, cx, cy));
}

TEST_F(DiffuseSprites, RejectsMoreThanItHasRoomFor) {
    const std::vector<DiffuseSprite> many(17, DiffuseSprite{0, 0.5f, 0, 0.1f, pack(255, 255, 255, 255)});
    EXPECT_THROW(draw(many), std::out_of_range);
}

TEST(DiffuseSpritesSetup, SpritesBeforeTheirPassAreRejected) {
    Renderer r(RenderSettings{kW, kH});
    const DiffuseSprite s{0, 0.5f, 0, 0.1f, 0xffffffffu};
    FrameView frame;
    frame.diffuse.sprites = std::span(&s, 1);
    EXPECT_THROW(r.render(frame), std::out_of_range);
}

}  // namespace
}  // namespace rivulet
