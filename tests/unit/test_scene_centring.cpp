// The driver renders every scene centred on its geometry (scene_centring.h): the move must
// keep every relation between camera, light and primitives, and leave a centred scene alone.
#include <gtest/gtest.h>

#include <string>

#include "scene_centring.h"
#include "scene_loader.h"

namespace {

Scene cornell() { return load_scene(std::string(RT_SOURCE_DIR) + "/common/scenes/cornell.json"); }

}  // namespace

TEST(SceneCentring, MovesEverythingByTheBoundingBoxCentre) {
    Scene far = cornell();
    const Vec3 shift(1.0e4f, -7.0e3f, 3.0e3f);
    for (Sphere& s : far.spheres) s.center += shift;
    for (AxisRect& r : far.rects) {  // the Cornell box's walls
        Vec3 corners[4];
        rect_corners(r, corners);
        for (Vec3& c : corners) c += shift;
        r = make_axis_rect(corners, rect_axis(r), r.material);
    }
    // A triangle and a convex quad too, across the box's front.
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(1, 1, 0.5f), d(0, 1, 0.5f);
    far.triangles.push_back(make_triangle(a + shift, b + shift, c + shift, 0));
    far.quads.push_back(make_convex_quad(a + shift, b + shift, c + shift, d + shift, 0));
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
    EXPECT_NEAR(centred.camera.position.x - centred.spheres[0].center.x,
                far.camera.position.x - far.spheres[0].center.x, 2e-3f);
    EXPECT_NEAR(centred.light.position.y - centred.triangles[0].v1.y,
                far.light.position.y - far.triangles[0].v1.y, 2e-3f);
    EXPECT_NEAR(centred.light.position.y - centred.rects[0].hi_u,
                far.light.position.y - far.rects[0].hi_u, 2e-3f);
    EXPECT_NEAR(centred.light.position.z - centred.quads[0].v3.z,
                far.light.position.z - far.quads[0].v3.z, 2e-3f);
    EXPECT_FLOAT_EQ(centred.camera.position.z, far.camera.position.z + o.z);
    // Primitives are rebuilt: their extent is the moved one's, no longer ~1e4, and each keeps
    // its kind, facing and material.
    EXPECT_LT(centred.triangles[0].extent, 10.0f);
    EXPECT_LT(centred.quads[0].extent, 10.0f);
    EXPECT_FLOAT_EQ(centred.triangles[0].normal.x, far.triangles[0].normal.x);
    EXPECT_NEAR(centred.quads[0].normal.y, far.quads[0].normal.y, 1e-6f);
    ASSERT_EQ(centred.rects.size(), far.rects.size());
    for (size_t i = 0; i < far.rects.size(); ++i) {
        EXPECT_LT(centred.rects[i].extent, 10.0f);
        EXPECT_EQ(centred.rects[i].axis_side, far.rects[i].axis_side);
        EXPECT_EQ(centred.rects[i].material, far.rects[i].material);
        EXPECT_NEAR(centred.rects[i].hi_u - centred.rects[i].lo_u,
                    far.rects[i].hi_u - far.rects[i].lo_u, 2e-3f);
    }
}

TEST(SceneCentring, ACentredSceneKeepsItsBits) {
    Scene s;
    s.spheres.push_back({Vec3(-1.0f, 2.0f, 0.5f), 1.0f, 0});
    s.spheres.push_back({Vec3(1.0f, -2.0f, -0.5f), 1.0f, 0});
    const Scene same = centre_scene(s);
    EXPECT_EQ(same.spheres[0].center.x, -1.0f);
    EXPECT_EQ(same.spheres[1].center.z, -0.5f);
}

TEST(SceneCentring, NoGeometryNoMove) {
    Scene empty;
    empty.camera.position = Vec3(5.0f, 6.0f, 7.0f);
    EXPECT_TRUE(is_black(centring_offset(empty)));
    EXPECT_EQ(centre_scene(empty).camera.position.x, 5.0f);
}
