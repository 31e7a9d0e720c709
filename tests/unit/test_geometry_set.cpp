// The geometry set (geometry_set.h): which kinds a scene has, which sets fit it, and that a
// renderer compiled for the scene's own set finds the same hits and renders the same bits as
// one compiled for every kind.
#include <gtest/gtest.h>

#include <cstring>
#include <random>
#include <string>

#include "cli.h"
#include "path_tracer.h"
#include "scene_loader.h"

namespace {

Scene cornell() { return load_scene(source_tree_path("common/scenes/cornell.json")); }

}  // namespace

TEST(PrimitiveKinds, KindsOfTheShippedScenes) {
    const Scene box = cornell();
    const GeometryKinds k = geometry_kinds(box.view());
    EXPECT_TRUE(k.has<Sphere>());
    EXPECT_FALSE(k.has<Triangle>());
    EXPECT_FALSE(k.has<ConvexQuad>());
    EXPECT_TRUE(k.has<AxisRect>());
    EXPECT_TRUE(k.fits<BoxGeometry>());
    EXPECT_TRUE(k.fits<AnyGeometry>());
    EXPECT_FALSE((k.fits<Kinds<Sphere, Triangle, ConvexQuad>>()));  // no rectangles
    const Scene showcase = load_scene(source_tree_path("common/scenes/showcase.json"));
    const GeometryKinds s = geometry_kinds(showcase.view());
    EXPECT_TRUE(s.has<Triangle>());
    EXPECT_FALSE(s.fits<BoxGeometry>());
    const GeometryKinds none = geometry_kinds(Scene().view());
    EXPECT_TRUE((none.fits<Kinds<>>()));
}

TEST(PrimitiveKinds, TheScenesOwnSetFindsTheSameHitsAndBits) {
    const Scene box = cornell();
    const SceneView v = box.view();
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> u(-0.2f, 1.2f);
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (int i = 0; i < 20000; ++i) {
        const Ray ray{{u(gen), u(gen), -u(gen)}, normalize(Vec3(n(gen), n(gen), n(gen)))};
        const Hit any = closest_hit(v, ray), own = closest_hit<BoxGeometry>(v, ray);
        ASSERT_EQ(any.kind, own.kind);
        ASSERT_EQ(any.index, own.index);
        ASSERT_EQ(any.t, own.t);
        ASSERT_EQ(occluded(v, ray, 0.5f), occluded<BoxGeometry>(v, ray, 0.5f));
    }
    RenderSettings rs;
    rs.width = rs.height = 8;
    rs.spp = 4;
    const Camera cam = box.camera.for_image(rs.width, rs.height);
    for (int y = 0; y < rs.height; ++y) {
        for (int x = 0; x < rs.width; ++x) {
            const Vec3 a = render_pixel(v, cam, rs, x, y);
            const Vec3 b = render_pixel<DiffuseOnly, BoxGeometry>(v, cam, rs, x, y);
            ASSERT_EQ(std::memcmp(&a, &b, sizeof a), 0) << x << ", " << y;
        }
    }
}

// A set without a kind does not test it: the renderer for spheres alone sees through walls.
TEST(PrimitiveKinds, ASetWithoutAKindLeavesItsLoopOut) {
    const Scene box = cornell();
    const Ray to_the_back_wall{{0.1f, 0.9f, -0.1f}, {0, 0, -1}};
    EXPECT_EQ(closest_hit(box.view(), to_the_back_wall).kind, primitive_kind<AxisRect>);
    using SpheresOnly = Kinds<Sphere>;
    EXPECT_FALSE(closest_hit<SpheresOnly>(box.view(), to_the_back_wall).found());
}
