// The same scene in more general primitives (common/cuda/general_geometry.h, host only): the
// rectangles as convex quads must render the same paths, bit for bit, with the same random
// numbers, since the quad test computes a rectangle's distance with the same operations and
// the quad carries the rectangle's normal.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "../../common/cuda/general_geometry.h"
#include "cli.h"
#include "path_tracer.h"
#include "scene_centring.h"
#include "scene_loader.h"

namespace {

Scene centred_cornell() {
    return centre_scene(load_scene(source_tree_path("common/scenes/cornell.json")));
}

bool same_bits(real a, real b) { return a == b && std::signbit(a) == std::signbit(b); }

}  // namespace

TEST(GeneralGeometry, RectangleQuadsCarryTheRectanglesNormalToTheSignOfZero) {
    const Scene scene = centred_cornell();
    const SceneView view = scene.view();
    ASSERT_GT(view.of<AxisRect>().count, 0);
    const SceneInForm quads(view, GeometryForm::Quads);
    ASSERT_EQ(quads.view.of<ConvexQuad>().count,
              view.of<ConvexQuad>().count + view.of<AxisRect>().count);
    for (int i = 0; i < view.of<AxisRect>().count; ++i) {
        const Vec3 expected = rect_normal(view.of<AxisRect>()[i]);
        const Vec3 got = quads.view.of<ConvexQuad>()[view.of<ConvexQuad>().count + i].normal;
        for (int c = 0; c < 3; ++c)
            EXPECT_TRUE(same_bits(got[c], expected[c])) << "rect " << i << " component " << c;
    }
    const SceneInForm triangles(view, GeometryForm::Triangles);
    for (int i = 0; i < view.of<AxisRect>().count; ++i) {
        const Vec3 expected = rect_normal(view.of<AxisRect>()[i]);
        for (int k = 0; k < 2; ++k) {
            const int index = view.of<Triangle>().count + 2 * (view.of<ConvexQuad>().count + i) + k;
            const Vec3 got = triangles.view.of<Triangle>()[index].normal;
            for (int c = 0; c < 3; ++c)
                EXPECT_TRUE(same_bits(got[c], expected[c])) << "rect " << i << " triangle " << k;
        }
    }
}

// The signed zeros matter: the cosine sampling's tangent frame depends on them, and a -0 in a
// wall's normal sends every bounce off that wall elsewhere.
TEST(GeneralGeometry, RectanglesAsQuadsRenderTheSameBits) {
    const Scene scene = centred_cornell();
    const SceneInForm quads(scene.view(), GeometryForm::Quads);
    RenderSettings settings;
    settings.width = settings.height = 16;
    settings.spp = 8;
    settings.bounces = 4;
    settings.seed = 5;
    const Camera camera = scene.camera.for_image(settings.width, settings.height);
    int different = 0;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            const Vec3 a = render_pixel(scene.view(), camera, settings, x, y);
            const Vec3 b = render_pixel(quads.view, camera, settings, x, y);
            different += !(a.x == b.x && a.y == b.y && a.z == b.z);
        }
    }
    EXPECT_EQ(different, 0);
}
