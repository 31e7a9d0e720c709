// The bounce step on its own, as a wavefront renderer would call it: what it does to the path
// state at a miss, a diffuse, a mirror and a glass hit, the shadow-ray request it makes, and a
// light sample measured from the surface point, not from the offset origin.
#include <gtest/gtest.h>

#include <cmath>

#include "path_tracer.h"
#include "scene_loader.h"

namespace {

// A floor y = 0 of half-size 10 and a light above it.
struct FloorScene {
    Scene scene;
    explicit FloorScene(MaterialType type = material_type<Diffuse>, Vec3 albedo = Vec3(0.5f)) {
        Material m{};
        m.type = type;
        m.albedo = albedo;
        m.ior = 1.5f;
        scene.materials.push_back(m);
        scene.material_names.push_back("floor");
        const Vec3 a(-10, 0, -10), b(-10, 0, 10), c(10, 0, 10), d(10, 0, -10);
        scene.of<Triangle>().push_back(make_triangle(a, b, c, 0));
        scene.of<Triangle>().push_back(make_triangle(a, c, d, 0));
        scene.has_light = true;
        scene.light.position = {1.0f, 2.0f, 0.5f};
        scene.light.intensity = Vec3(3.0f);
        scene.background = {0.1f, 0.2f, 0.3f};
    }
    SceneView view() const { return scene.view(); }
};

const SampleStream kRng(1, 2, 3);

Vec3 expected_direct(Vec3 p, Vec3 light, Vec3 intensity, Vec3 albedo) {
    const Vec3 to = light - p;
    const float d2 = length_squared(to);
    return albedo * intensity * ((to.y / std::sqrt(d2)) / (kPi * d2));
}

}  // namespace

// However far the shadow ray's origin is pushed off the surface, the light's distance and
// cosine are the surface point's: an offset that grows with |p| must not change brightness.
TEST(BounceStep, LightIsMeasuredFromTheSurfacePoint) {
    const FloorScene fs;
    const SceneView v = fs.view();
    const Vec3 p(0.2f, 0.0f, -0.3f), n(0, 1, 0);
    const Vec3 want = expected_direct(p, v.light.position, v.light.intensity, Vec3(0.5f));
    for (float lift : {1e-6f, 1e-3f, 0.1f, 0.5f}) {
        const Vec3 got = direct_light(v, p, p + n * lift, n, Vec3(0.5f));
        EXPECT_NEAR(got.x, want.x, 1e-6f * want.x) << "offset " << lift;
    }
}

// The shadow ray runs from the offset origin along the surface point's direction to the light
// and ends where it passes the light: t_max = d - (origin - p).wi.
TEST(BounceStep, ShadowRayEndsWhereItPassesTheLight) {
    const FloorScene fs;
    const SceneView v = fs.view();
    const Vec3 p(0.2f, 0.0f, -0.3f), n(0, 1, 0), origin = p + n * 0.25f;
    ShadowRay shadow;
    ASSERT_TRUE(sample_light(v, p, origin, n, Vec3(0.5f), shadow));
    const Vec3 to_light = v.light.position - p;
    const Vec3 wi = normalize(to_light);
    EXPECT_EQ(shadow.ray.origin.y, origin.y);
    EXPECT_NEAR(dot(shadow.ray.direction, wi), 1.0f, 1e-6f);
    EXPECT_NEAR(shadow.t_max, length(to_light) - 0.25f * wi.y, 1e-5f);
    // Light behind the surface: no request.
    EXPECT_FALSE(sample_light(v, p, p - n * 0.25f, -n, Vec3(0.5f), shadow));
}

TEST(BounceStep, AMissAddsTheBackgroundAndEndsThePath) {
    const FloorScene fs;
    PathState path = start_path({{0, 1, 0}, {0, 1, 0}}, 4);
    path.throughput = Vec3(0.5f);
    ShadowRay shadow;
    EXPECT_FALSE(bounce_step(fs.view(), Hit{}, kRng, 4, path, shadow));
    EXPECT_FALSE(path.alive);
    EXPECT_EQ(path.radiance.z, 0.5f * 0.3f);
}

// A diffuse hit asks for a shadow ray weighted by the throughput so far, then continues with
// the albedo in the throughput and a ray from the offset point, unless the budget is spent.
TEST(BounceStep, DiffuseHitRequestsTheLightAndContinues) {
    const FloorScene fs;
    const SceneView v = fs.view();
    const Ray down{{0.2f, 1.0f, -0.3f}, {0, -1, 0}};
    const Hit hit = closest_hit(v, down);
    ASSERT_TRUE(hit.found());
    for (int max_bounces : {1, 3}) {
        PathState path = start_path(down, max_bounces);
        path.throughput = Vec3(0.8f);
        ShadowRay shadow;
        ASSERT_TRUE(bounce_step(v, hit, kRng, max_bounces, path, shadow));
        const Vec3 p(0.2f, 0.0f, -0.3f);
        const Vec3 want = expected_direct(p, v.light.position, v.light.intensity, Vec3(0.5f));
        EXPECT_NEAR(shadow.radiance.x, 0.8f * want.x, 1e-6f * want.x);
        EXPECT_GT(shadow.ray.origin.y, 0.0f);  // from the offset point above the floor
        EXPECT_EQ(path.bounce, 1);
        EXPECT_EQ(path.radiance.x, 0.0f);  // the light is added only once the shadow ray is clear
        EXPECT_EQ(path.alive, max_bounces > 1);
        if (path.alive) {
            EXPECT_FLOAT_EQ(path.throughput.x, 0.8f * 0.5f);
            EXPECT_GT(path.ray.origin.y, 0.0f);
            EXPECT_GT(path.ray.direction.y, 0.0f);  // into the upper hemisphere
        }
    }
}

// Specular hits ask for no shadow ray; at the last bounce they just end the path.
TEST(BounceStep, SpecularHitsRequestNoLight) {
    for (MaterialType type : {material_type<Mirror>, material_type<Glass>}) {
        const FloorScene fs(type, Vec3(0.9f));
        const SceneView v = fs.view();
        const Ray slant{{0.0f, 1.0f, 0.0f}, normalize(Vec3(0.3f, -1.0f, 0.1f))};
        const Hit hit = closest_hit(v, slant);
        for (int max_bounces : {1, 2}) {
            PathState path = start_path(slant, max_bounces);
            ShadowRay shadow;
            EXPECT_FALSE(bounce_step(v, hit, kRng, max_bounces, path, shadow));
            EXPECT_EQ(path.alive, max_bounces > 1);
            if (type == material_type<Mirror> && path.alive) {
                EXPECT_FLOAT_EQ(path.ray.direction.y, -slant.direction.y);  // reflected
                EXPECT_FLOAT_EQ(path.throughput.x, 0.9f);
            }
        }
    }
}

// trace_path is the loop of closest hit, bounce step and shadow ray: the same bits.
TEST(BounceStep, TracePathIsTheLoopAroundTheStep) {
    const FloorScene fs;
    const SceneView v = fs.view();
    const Ray ray{{0.0f, 1.0f, 0.0f}, normalize(Vec3(0.3f, -1.0f, 0.1f))};
    PathState path = start_path(ray, 3);
    while (path.alive) {
        const Hit hit = closest_hit(v, path.ray);
        ShadowRay shadow;
        if (bounce_step(v, hit, kRng, 3, path, shadow) && !occluded(v, shadow.ray, shadow.t_max))
            path.radiance += shadow.radiance;
    }
    const Vec3 l = trace_path(v, ray, kRng, 3);
    EXPECT_EQ(l.x, path.radiance.x);
    EXPECT_EQ(l.y, path.radiance.y);
    EXPECT_EQ(l.z, path.radiance.z);
    EXPECT_GT(l.x, 0.0f);
}
