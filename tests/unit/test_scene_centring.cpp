// The driver renders every scene centred on its geometry (scene_centring.h): the move must
// keep every relation between camera, light and primitives, and leave a centred scene alone.
#include <gtest/gtest.h>

#include <string>

#include "cli.h"
#include "scene_centring.h"
#include "scene_loader.h"

namespace {

Scene cornell() { return load_scene(source_tree_path("common/scenes/cornell.json")); }

}  // namespace

TEST(SceneCentring, MovesEverythingByTheBoundingBoxCentre) {
    Scene far = cornell();
    const Vec3 shift(1.0e4f, -7.0e3f, 3.0e3f);
    for (Sphere& s : far.of<Sphere>()) s.center += shift;
    for (AxisRect& r : far.of<AxisRect>()) {  // the Cornell box's walls
        Vec3 corners[4];
        rect_corners(r, corners);
        for (Vec3& c : corners) c += shift;
        r = make_axis_rect(corners, rect_axis(r), r.material);
    }
    // A triangle and a convex quad too, across the box's front.
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0.5f), d(0, 1, 0.5f);
    far.of<Triangle>().push_back(make_triangle(a + shift, b + shift, c + shift, 0));
    far.of<ConvexQuad>().push_back(make_convex_quad(a + shift, b + shift, c + shift, d + shift, 0));
    far.camera.position += shift;
    far.camera.look_at += shift;
    far.light.position += shift;

    const Scene centred = centre_scene(far);
    const Vec3 o = centring_offset(far);
    // The geometry's box is now centred on the origin (to the rounding of the far coordinates).
    EXPECT_NEAR(centring_offset(centred).x, 0.0f, 2e-3f);
    EXPECT_NEAR(centring_offset(centred).y, 0.0f, 2e-3f);
    EXPECT_NEAR(centring_offset(centred).z, 0.0f, 2e-3f);
    // Camera, light and primitives moved together: their differences are unchanged.
    EXPECT_NEAR(centred.camera.position.x - centred.of<Sphere>()[0].center.x,
                far.camera.position.x - far.of<Sphere>()[0].center.x, 2e-3f);
    EXPECT_NEAR(centred.light.position.y - centred.of<Triangle>()[0].v1.y,
                far.light.position.y - far.of<Triangle>()[0].v1.y, 2e-3f);
    EXPECT_NEAR(centred.light.position.y - centred.of<AxisRect>()[0].hi_u,
                far.light.position.y - far.of<AxisRect>()[0].hi_u, 2e-3f);
    EXPECT_NEAR(centred.light.position.z - centred.of<ConvexQuad>()[0].v3.z,
                far.light.position.z - far.of<ConvexQuad>()[0].v3.z, 2e-3f);
    EXPECT_FLOAT_EQ(centred.camera.position.z, far.camera.position.z + o.z);
    // Primitives are rebuilt: their extent is the moved one's, no longer ~1e4, and each keeps
    // its kind, facing and material.
    EXPECT_LT(centred.of<Triangle>()[0].extent, 10.0f);
    EXPECT_LT(centred.of<ConvexQuad>()[0].extent, 10.0f);
    EXPECT_FLOAT_EQ(centred.of<Triangle>()[0].normal.x, far.of<Triangle>()[0].normal.x);
    EXPECT_NEAR(centred.of<ConvexQuad>()[0].normal.y, far.of<ConvexQuad>()[0].normal.y, 1e-6f);
    ASSERT_EQ(centred.of<AxisRect>().size(), far.of<AxisRect>().size());
    for (size_t i = 0; i < far.of<AxisRect>().size(); ++i) {
        EXPECT_LT(centred.of<AxisRect>()[i].extent, 10.0f);
        EXPECT_EQ(centred.of<AxisRect>()[i].axis_side, far.of<AxisRect>()[i].axis_side);
        EXPECT_EQ(centred.of<AxisRect>()[i].material, far.of<AxisRect>()[i].material);
        EXPECT_NEAR(centred.of<AxisRect>()[i].hi_u - centred.of<AxisRect>()[i].lo_u,
                    far.of<AxisRect>()[i].hi_u - far.of<AxisRect>()[i].lo_u, 2e-3f);
    }
}

TEST(SceneCentring, ACentredSceneKeepsItsBits) {
    Scene s;
    s.of<Sphere>().push_back({Vec3(-1.0f, 2.0f, 0.5f), 1.0f, 0});
    s.of<Sphere>().push_back({Vec3(1.0f, -2.0f, -0.5f), 1.0f, 0});
    const Scene same = centre_scene(s);
    EXPECT_EQ(same.of<Sphere>()[0].center.x, -1.0f);
    EXPECT_EQ(same.of<Sphere>()[1].center.z, -0.5f);
}

TEST(SceneCentring, NoGeometryNoMove) {
    Scene empty;
    empty.camera.position = Vec3(5.0f, 6.0f, 7.0f);
    EXPECT_TRUE(is_black(centring_offset(empty)));
    EXPECT_EQ(centre_scene(empty).camera.position.x, 5.0f);
}
