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
    for (Triangle& t : far.triangles)
        t = make_triangle(t.v0 + shift, t.v1 + shift, t.v2 + shift, t.material);
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
    EXPECT_FLOAT_EQ(centred.camera.position.z, far.camera.position.z + o.z);
    // Triangles are rebuilt: their extent is the moved triangle's, no longer ~1e4.
    EXPECT_LT(centred.triangles[0].extent, 10.0f);
    EXPECT_FLOAT_EQ(centred.triangles[0].normal.x, far.triangles[0].normal.x);
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
