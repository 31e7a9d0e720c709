// What keeps paths inside closed specular rooms and scenes right wherever they are placed:
// reflected directions stay unit length over many bounces, an origin on a triangle's edge steps
// off every edge it lies on, a light at the surface point gives no sample (never NaN), and the
// loader and centring work from the file's numbers in double.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "errors.h"
#include "path_tracer.h"
#include "scene_centring.h"
#include "scene_loader.h"

namespace {

// A mirror floor y = 0 (two triangles) under a camera ray.
Scene mirror_floor() {
    Scene scene;
    Material m{};
    m.type = material_type<Mirror>;
    m.albedo = Vec3(1.0f);
    scene.materials.push_back(m);
    scene.material_names.push_back("mirror");
    const Vec3 a(-1, 0, -1), b(-1, 0, 1), c(1, 0, 1), d(1, 0, -1);
    scene.of<Triangle>().push_back(make_triangle(a, b, c, 0));
    scene.of<Triangle>().push_back(make_triangle(a, c, d, 0));
    return scene;
}

const SampleStream kRng(1, 2, 3);

std::string parse_error(const std::string& text) {
    try {
        parse_scene(text, "case.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

}  // namespace

// A reflection of a unit direction rounds to a length 1 +- a few ulps; the bounce step
// renormalises it, so 64 reflections inside a mirror sphere leave it unit to an ulp or two,
// and every one of them finds the sphere again. Unnormalised, the length drifted and the path
// left the sphere (the sphere test assumes a unit direction).
TEST(SpecularBounce, ReflectedDirectionsStayUnitLength) {
    Scene scene;
    Material m{};
    m.type = material_type<Mirror>;
    m.albedo = Vec3(1.0f);
    scene.materials.push_back(m);
    scene.material_names.push_back("mirror");
    scene.of<Sphere>().push_back({Vec3(0.13f, -0.07f, 0.05f), 1.37f, 0});
    const SceneView v = scene.view();
    for (int k = 0; k < 50; ++k) {
        const Vec3 d = normalize(Vec3(0.31f + 0.05f * k, -1.0f + 0.03f * k, 0.17f - 0.02f * k));
        PathState path = start_path({{0.41f, -0.27f, 0.19f}, d}, 64);
        int bounces = 0;
        while (path.alive) {
            const Hit hit = closest_hit(v, path.ray);
            ASSERT_TRUE(hit.found()) << "ray " << k << " escaped after " << bounces << " bounces";
            ShadowRay shadow;
            bounce_step(v, hit, kRng, 64, path, shadow);
            ++bounces;
            if (path.alive) {
                ASSERT_NEAR(length(path.ray.direction), 1.0f, 2.5e-7f) << bounces;
            }
        }
        EXPECT_EQ(bounces, 64);
    }
}

// A point on an edge steps `margin` inward across that edge; on a corner, across both; inside,
// not at all. The step lies in the triangle's plane.
TEST(StepOffEdges, StepsInsideEveryEdgeThePointLiesOn) {
    const Triangle tri = make_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    const float margin = 1e-3f;
    const Vec3 on_bottom = step_off_edges(tri, {0.5f, 0.0f, 0.0f}, margin);
    EXPECT_NEAR(on_bottom.x, 0.0f, 1e-9f);
    EXPECT_NEAR(on_bottom.y, margin, 1e-9f);
    EXPECT_EQ(on_bottom.z, 0.0f);
    const Vec3 at_corner = step_off_edges(tri, {0.0f, 0.0f, 0.0f}, margin);
    EXPECT_NEAR(at_corner.x, margin, 1e-9f);
    EXPECT_NEAR(at_corner.y, margin, 1e-9f);
    const Vec3 on_diagonal = step_off_edges(tri, {0.5f, 0.5f, 0.0f}, margin);
    EXPECT_NEAR(on_diagonal.x, -margin / std::sqrt(2.0f), 1e-8f);
    EXPECT_NEAR(on_diagonal.y, -margin / std::sqrt(2.0f), 1e-8f);
    EXPECT_TRUE(is_black(step_off_edges(tri, {0.25f, 0.25f, 0.0f}, margin)));
    // Just outside an edge (rounding): still stepped inside.
    EXPECT_GT(step_off_edges(tri, {0.5f, -1e-7f, 0.0f}, margin).y, 0.0f);
}

// A mirror hit exactly on the edge of a closed room's floor starts its next ray inside the
// wall's plane too: the origin lies strictly in front of both faces.
TEST(StepOffEdges, AMirrorHitOnARoomsEdgeStartsInFrontOfBothFaces) {
    Scene scene = mirror_floor();
    // A wall x = 1 facing -x, meeting the floor at the edge x = 1, y = 0.
    scene.of<Triangle>().push_back(make_triangle({1, 0, -1}, {1, 0, 1}, {1, 1, 1}, 0));
    const SceneView v = scene.view();
    // 0.4f + 0.6f and 0.8f - 0.8f round to 1 and 0: the hit lies exactly on the edge.
    const Ray ray{{0.4f, 0.8f, 0.25f}, {0.6f, -0.8f, 0.0f}};
    Hit hit;
    hit.t = 1.0f;
    hit.kind = primitive_kind<Triangle>;
    hit.index = 1;  // the floor's second triangle holds the edge x = 1
    ASSERT_EQ(ray.at(hit.t).x, 1.0f);
    ASSERT_EQ(ray.at(hit.t).y, 0.0f);
    PathState path = start_path(ray, 4);
    ShadowRay shadow;
    bounce_step(v, hit, kRng, 4, path, shadow);
    EXPECT_GT(path.ray.origin.y, 0.0f);  // in front of the floor
    EXPECT_LT(path.ray.origin.x, 1.0f);  // in front of the wall
}

// The same room with a floor and a wall of each flat kind: a rectangle or a convex quad steps
// off its edges as a triangle does, and for the specular bounce step lane by lane too
// (tests/labs/test_properties.py's rooms of quads). Without the step, the next ray starts in
// the wall's plane and leaves through it.
TEST(StepOffEdges, RectanglesAndQuadsStepOffTheirEdgesToo) {
    const Vec3 a(-1, 0, -1), b(-1, 0, 1), c(1, 0, 1), d(1, 0, -1);          // the floor
    const Vec3 e(1, 0, -1), f(1, 0, 1), g(1, 1, 1), h(1, 1, -1);            // the wall x = 1
    for (const PrimitiveKind kind : {primitive_kind<AxisRect>, primitive_kind<ConvexQuad>}) {
        Scene scene = mirror_floor();
        scene.of<Triangle>().clear();
        if (kind == primitive_kind<AxisRect>) {
            const Vec3 floor[4] = {a, b, c, d}, wall[4] = {e, f, g, h};
            scene.of<AxisRect>() = {make_axis_rect(floor, 1, 0), make_axis_rect(wall, 0, 0)};
        } else {
            scene.of<ConvexQuad>() = {make_convex_quad(a, b, c, d, 0),
                                      make_convex_quad(e, f, g, h, 0)};
        }
        const SceneView v = scene.view();
        const Ray ray{{0.4f, 0.8f, 0.25f}, {0.6f, -0.8f, 0.0f}};
        const Hit hit = closest_hit(v, ray);
        ASSERT_EQ(hit.kind, kind);
        ASSERT_EQ(hit.index, 0) << "the floor";
        ASSERT_EQ(ray.at(hit.t).x, 1.0f);
        ASSERT_EQ(ray.at(hit.t).y, 0.0f);
        PathState path = start_path(ray, 4);
        ShadowRay shadow;
        bounce_step(v, hit, kRng, 4, path, shadow);
        EXPECT_GT(path.ray.origin.y, 0.0f);  // in front of the floor
        EXPECT_LT(path.ray.origin.x, 1.0f);  // in front of the wall
        EXPECT_EQ(closest_hit(v, path.ray).index, 1) << "the reflected ray meets the wall";
    }
}

// A light exactly at the surface point (distance 0) or within the point's own rounding gives
// no sample, and nothing that sample_light returns is NaN.
TEST(SampleLight, ALightAtTheSurfacePointGivesNoSample) {
    Scene scene = mirror_floor();
    scene.materials[0].type = material_type<Diffuse>;
    scene.has_light = true;
    scene.light.intensity = Vec3(1.0f);
    const Vec3 n(0, 1, 0);
    for (Vec3 p : {Vec3(0.25f, 0.0f, -0.5f), Vec3(0.0f, 0.0f, 0.0f), Vec3(1.0f, 0.0f, 1.0f)}) {
        scene.light.position = p;
        ShadowRay shadow;
        EXPECT_FALSE(sample_light(scene.view(), p, offset_ray_origin(p, n, 1.0f, 1.0f), n,
                                  Vec3(0.5f), shadow));
        // 1 ulp above a point 5000 from the origin: the rounding's direction, not the light's.
        const Vec3 far(5000.0f, 0.0f, 5000.0f);
        scene.light.position = Vec3(far.x, std::nextafter(0.0f, 1.0f), far.z);
        EXPECT_FALSE(sample_light(scene.view(), far, offset_ray_origin(far, n, 1.0f, 1e4f), n,
                                  Vec3(0.5f), shadow));
    }
    // A light 1e-6 above a point near the origin is resolved and lights it.
    const Vec3 p(0.25f, 0.0f, -0.5f);
    scene.light.position = p + n * 1e-6f;
    ShadowRay shadow;
    ASSERT_TRUE(
        sample_light(scene.view(), p, offset_ray_origin(p, n, 1.0f, 1.0f), n, Vec3(0.5f), shadow));
    EXPECT_TRUE(std::isfinite(shadow.radiance.x) && shadow.radiance.x > 0.0f);
}

// Centring works from the file's numbers: a scene moved by an offset that float cannot hold
// exactly centres to the same floats as the unmoved one, camera aim included.
TEST(WrittenCoordinates, AGenericOffsetCentresToTheUnmovedScene) {
    const auto scene_text = [](double dx, double dy, double dz) {
        const auto p = [&](double x, double y, double z) {
            char text[128];
            std::snprintf(text, sizeof text, "[%.17g, %.17g, %.17g]", x + dx, y + dy, z + dz);
            return std::string(text);
        };
        return "{\"camera\": {\"position\": " + p(0, 1, 0) +
               ", \"look_at\": " + p(0, 1 - 0.8e-3, -0.6e-3) +
               "}, \"light\": {\"position\": " + p(0.3, 1e-2, -0.7) +
               ", \"intensity\": [1, 1, 1]}, \"materials\": {\"w\": {\"type\": \"diffuse\", "
               "\"albedo\": [0.5, 0.5, 0.5]}}, \"quads\": [{\"vertices\": [" +
               p(-10, 0, -10) + ", " + p(-10, 0, 10) + ", " + p(10, 0, 10) + ", " + p(10, 0, -10) +
               "], \"material\": \"w\"}]}";
    };
    const Scene base = centre_scene(parse_scene(scene_text(0, 0, 0), "base.json"));
    const Scene moved =
        centre_scene(parse_scene(scene_text(12345.678, -8765.4321, 3456.789), "moved.json"));
    EXPECT_NEAR(moved.light.position.y, base.light.position.y, 1e-9f);
    EXPECT_NEAR(moved.light.position.x, base.light.position.x, 1e-9f);
    ASSERT_EQ(moved.of<AxisRect>().size(), 1u);  // the floor, in both
    ASSERT_EQ(base.of<AxisRect>().size(), 1u);
    EXPECT_EQ(moved.of<AxisRect>()[0].plane, base.of<AxisRect>()[0].plane);
    EXPECT_EQ(moved.of<AxisRect>()[0].lo_v, base.of<AxisRect>()[0].lo_v);
    EXPECT_EQ(moved.of<AxisRect>()[0].hi_u, base.of<AxisRect>()[0].hi_u);
    const Camera a = base.camera.for_image(16, 16), b = moved.camera.for_image(16, 16);
    const Vec3 da = a.ray_through(8, 8).direction, db = b.ray_through(8, 8).direction;
    EXPECT_GT(dot(da, db), 1.0f - 1e-6f) << "the moved camera aims elsewhere";
}

// At scale 1e-25 the refusal names the size, not the camera; a look_at 1e-23 from a camera at
// the origin is a direction, as the file's numbers differ.
TEST(WrittenCoordinates, RefusalsGiveTheTrueReasonAtAnyScale) {
    const std::string tiny =
        R"({"camera": {"position": [0, 0, 5e-25], "look_at": [0, 0, 0]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
            "spheres": [{"center": [0, 0, 0], "radius": 1e-25, "material": "w"}]})";
    const std::string message = parse_error(tiny);
    EXPECT_NE(message.find("radius"), std::string::npos) << message;
    EXPECT_EQ(message.find("camera position"), std::string::npos) << message;
    const Scene close = parse_scene(
        R"({"camera": {"position": [0, 0, 0], "look_at": [0, 1e-23, -1e-23]},
            "materials": {"w": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
            "spheres": [{"center": [0, 0, 0], "radius": 1, "material": "w"}]})",
        "close.json");
    const Vec3 d = close.camera.for_image(4, 4).ray_through(2, 2).direction;
    EXPECT_NEAR(d.y, std::sqrt(0.5f), 1e-6f);
    EXPECT_NEAR(d.z, -std::sqrt(0.5f), 1e-6f);
}

#if !defined(RT_DOUBLE)
// A detail below 2^-13 of the centred scene's reach (128 ray offsets) is refused in float,
// naming the double build; at 2^-12 it loads.
TEST(WrittenCoordinates, MixedScalesBeyondFloatAreRefused) {
    const auto scene = [](double radius) {
        char text[512];
        std::snprintf(text, sizeof text,
                      R"({"camera": {"position": [0, 1, 3], "look_at": [0, 0, 0]},
                          "materials": {"w": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
                          "spheres": [{"center": [0, 0, 0], "radius": %.17g, "material": "w"}],
                          "quads": [{"vertices": [[-1e4, 0, -1e4], [-1e4, 0, 1e4],
                                     [1e4, 0, 1e4], [1e4, 0, -1e4]], "material": "w"}]})",
                      radius);
        return std::string(text);
    };
    const std::string message = parse_error(scene(1e-4));
    EXPECT_NE(message.find("/spheres/0/radius"), std::string::npos) << message;
    EXPECT_NE(message.find("double places it"), std::string::npos) << message;
    EXPECT_NE(message.find("lab01-ref"), std::string::npos) << message;
    EXPECT_NO_THROW(parse_scene(scene(1e4 / (1 << 12)), "fine.json"));
    EXPECT_THROW(parse_scene(scene(1e4 / (1 << 14)), "near.json"), PrecisionError);
}
#endif
