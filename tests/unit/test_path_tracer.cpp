// The path tracer on tiny scenes built in code, where the answer is known exactly: direct
// light from a point source, shadows (glass included), escaping rays, mirrors, the white
// furnace, and a deterministic, seed-dependent render_pixel.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cli.h"
#include "path_tracer.h"
#include "scene_loader.h"

namespace {

// A scene under construction; view() is what the tracer reads.
struct TestScene {
    Scene scene;

    int material(MaterialType type, Vec3 albedo, float ior = 1.5f) {
        Material m{};  // field by field: the tests survive new members
        m.type = type;
        m.albedo = albedo;
        m.ior = ior;
        scene.materials.push_back(m);
        scene.material_names.push_back("m" + std::to_string(scene.materials.size()));
        return static_cast<int>(scene.materials.size()) - 1;
    }
    // The square [-h, h]^2 of the plane y = 0, facing +y, as two triangles.
    void floor(int m, float h = 10.0f) {
        const Vec3 a(-h, 0, -h), b(-h, 0, h), c(h, 0, h), d(h, 0, -h);
        scene.of<Triangle>().push_back(make_triangle(a, b, c, m));
        scene.of<Triangle>().push_back(make_triangle(a, c, d, m));
    }
    void sphere(Vec3 c, float r, int m) {
        Sphere s{};
        s.center = c;
        s.radius = r;
        s.material = m;
        scene.of<Sphere>().push_back(s);
    }
    void light(Vec3 p, Vec3 intensity) {
        scene.has_light = true;
        scene.light.position = p;
        scene.light.intensity = intensity;
    }
    SceneView view() const { return scene.view(); }
};

const SampleStream kRng(0, 0, 0);

Ray ray_to(Vec3 from, Vec3 to) { return {from, normalize(to - from)}; }

// direct_light at floor point p (the floor is 10 units wide: its extent), the shadow ray from
// the offset origin a path arriving from 1 unit away would use.
Vec3 direct_light_from(const SceneView& v, Vec3 p, Vec3 n, Vec3 albedo) {
    return direct_light(v, p, offset_ray_origin(p, n, 1.0f, 10.0f), n, albedo);
}

// rho/pi * I * cos(theta) / d^2 for a point p on the floor (normal +y).
Vec3 expected_direct(Vec3 p, Vec3 light, Vec3 intensity, Vec3 albedo) {
    const Vec3 to = light - p;
    const float d2 = length_squared(to);
    const float cos_theta = to.y / std::sqrt(d2);
    return albedo * intensity * (cos_theta / (kPi * d2));
}

void expect_rel_near(Vec3 a, Vec3 b, float rel) {
    EXPECT_NEAR(a.x, b.x, rel * std::fabs(b.x) + 1e-30f);
    EXPECT_NEAR(a.y, b.y, rel * std::fabs(b.y) + 1e-30f);
    EXPECT_NEAR(a.z, b.z, rel * std::fabs(b.z) + 1e-30f);
}

void expect_exact(Vec3 a, Vec3 b) {
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.y, b.y);
    EXPECT_EQ(a.z, b.z);
}

// The Cornell scene with every length multiplied by s and the light by s^2, so that every
// radiance is unchanged.
Scene scaled(const Scene& base, float s) {
    Scene out = base;
    out.camera.position = base.camera.position * s;
    out.camera.look_at = base.camera.look_at * s;
    out.light.position = base.light.position * s;
    out.light.intensity = base.light.intensity * (s * s);
    for (Sphere& sp : out.of<Sphere>()) {
        sp.center = sp.center * s;
        sp.radius *= s;
    }
    for (Triangle& t : out.of<Triangle>())
        t = make_triangle(t.v0 * s, t.v1 * s, t.v2 * s, t.material);
    for (ConvexQuad& q : out.of<ConvexQuad>())
        q = make_convex_quad(q.v0 * s, q.v1 * s, q.v2 * s, q.v3 * s, q.material);
    for (AxisRect& r : out.of<AxisRect>()) {
        Vec3 corners[4];
        rect_corners(r, corners);
        for (Vec3& c : corners) c = c * s;
        r = make_axis_rect(corners, rect_axis(r), r.material);
    }
    out.written = {};  // the file's points no longer stand for these
    return out;
}

}  // namespace

TEST(PathTracer, ClosestHitPicksTheNearestPrimitive) {
    TestScene ts;
    const int m = ts.material(material_type<Diffuse>, Vec3(0.5f));
    ts.floor(m);                      // triangles 0, 1 at y = 0
    ts.sphere({0, 2, 0}, 0.5f, m);    // sphere 0: top at y = 2.5
    ts.sphere({0, 5, 0}, 0.5f, m);    // sphere 1 above it
    const SceneView v = ts.view();
    const Hit down = closest_hit(v, {{0, 10, 0}, {0, -1, 0}});
    EXPECT_EQ(down.kind, primitive_kind<Sphere>);
    EXPECT_EQ(down.index, 1);
    EXPECT_FLOAT_EQ(down.t, 4.5f);
    const Hit floor_hit = closest_hit(v, {{3, 10, 0.5f}, {0, -1, 0}});
    EXPECT_EQ(floor_hit.kind, primitive_kind<Triangle>);
    EXPECT_GE(floor_hit.index, 0);
    EXPECT_FLOAT_EQ(floor_hit.t, 10.0f);
    // Between the spheres, looking down: the lower sphere, not the floor behind it.
    const Hit mid = closest_hit(v, {{0, 3.5f, 0}, {0, -1, 0}});
    EXPECT_EQ(mid.kind, primitive_kind<Sphere>);
    EXPECT_EQ(mid.index, 0);
    EXPECT_FLOAT_EQ(mid.t, 1.0f);
    // A triangle in front of a sphere.
    const Hit up = closest_hit(v, {{0, -3, 0}, {0, 1, 0}});
    EXPECT_EQ(up.kind, primitive_kind<Triangle>);
    EXPECT_GE(up.index, 0);
    EXPECT_FLOAT_EQ(up.t, 3.0f);
    const Hit none = closest_hit(v, {{0, 10, 0}, {0, 1, 0}});
    EXPECT_FALSE(none.found());
    const SurfacePoint sp = surface_at(v, {{0, 10, 0}, {0, -1, 0}}, down);
    EXPECT_NEAR(sp.normal.y, 1.0f, 1e-6f);
    EXPECT_NEAR(sp.position.y, 5.5f, 1e-5f);
}

TEST(PathTracer, OccludedRespectsTMax) {
    TestScene ts;
    const int m = ts.material(material_type<Diffuse>, Vec3(0.5f));
    ts.sphere({0, 5, 0}, 1.0f, m);
    ts.floor(m);
    const SceneView v = ts.view();
    const Ray up{{0, 1, 0}, {0, 1, 0}};
    EXPECT_TRUE(occluded(v, up, 100.0f));
    EXPECT_TRUE(occluded(v, up, 3.01f));
    EXPECT_FALSE(occluded(v, up, 3.0f));  // the blocker starts at t = 3
    EXPECT_FALSE(occluded(v, {{3, 1, 0}, {0, 1, 0}}, 100.0f));
    EXPECT_TRUE(occluded(v, {{3, 1, 0}, {0, -1, 0}}, 100.0f));  // the floor
    EXPECT_FALSE(occluded(v, {{3, 1, 0}, {0, -1, 0}}, 0.99f));
}

TEST(PathTracer, PointLightOnDiffusePlaneIsExact) {
    TestScene ts;
    const Vec3 albedo(0.5f, 0.6f, 0.7f), intensity(1.0f, 2.0f, 3.0f), light(0.3f, 2.0f, -0.4f);
    ts.floor(ts.material(material_type<Diffuse>, albedo));
    ts.light(light, intensity);
    const SceneView v = ts.view();
    for (const Vec3 p : {Vec3(0.2f, 0, 0.1f), Vec3(-3, 0, 4), Vec3(0.3f, 0, -0.4f)}) {
        const Vec3 expected = expected_direct(p, light, intensity, albedo);
        const Ray ray = ray_to({1, 1, 1}, p);
        expect_rel_near(trace_path(v, ray, kRng, 1), expected, 1e-4f);
        // With more bounces the second ray escapes into a black background: nothing more.
        expect_rel_near(trace_path(v, ray, kRng, 2), expected, 1e-4f);
        expect_rel_near(trace_path(v, ray, SampleStream(9, 9, 9), 5), expected, 1e-4f);
        // direct_light itself, from the point (and a normal facing the light).
        expect_rel_near(direct_light_from(v, p, {0, 1, 0}, albedo), expected, 1e-5f);
    }
    // Directly below the light: cos = 1, d = 2.
    const Vec3 below(0.3f, 0.0f, -0.4f);
    expect_rel_near(direct_light_from(v, below, {0, 1, 0}, albedo),
                    albedo * intensity * (1.0f / (kPi * 4.0f)), 1e-6f);
}

TEST(PathTracer, LightBehindTheSurfaceGivesNothing) {
    TestScene ts;
    ts.floor(ts.material(material_type<Diffuse>, Vec3(0.8f)));
    ts.light({0, 2, 0}, Vec3(5.0f));
    const SceneView v = ts.view();
    // Seen from below, the floor's lit side faces away: black, no light leaks through.
    expect_exact(trace_path(v, ray_to({1, -1, 1}, {0.2f, 0, 0.1f}), kRng, 1), Vec3(0.0f));
    expect_exact(direct_light_from(v, {0, 0, 0}, {0, -1, 0}, Vec3(0.8f)), Vec3(0.0f));
    // A light exactly in the tangent plane gives cos = 0.
    expect_exact(direct_light_from(v, {0, 0, 0}, {1, 0, 0}, Vec3(0.8f)), Vec3(0.0f));
}

// A light at the type's largest intensity just above a floor of albedo (1, 0, 1): the light's
// term saturates at kRealMax instead of overflowing to inf, so a throughput with a zero
// channel where the term has a full one gives 0, not 0 * inf = NaN.
TEST(PathTracer, TheLightTermSaturatesAtTheLargestValue) {
    TestScene ts;
    const Vec3 albedo(1.0f, 0.0f, 1.0f);
    ts.floor(ts.material(material_type<Diffuse>, albedo));
    ts.light({0, real(0.01), 0}, Vec3(kRealMax));
    const Vec3 lit = direct_light_from(ts.view(), {0, 0, 0}, {0, 1, 0}, albedo);
    EXPECT_EQ(lit.x, kRealMax);
    EXPECT_EQ(lit.y, real(0));
    EXPECT_EQ(lit.z, kRealMax);
    const Vec3 weighted = Vec3(0.0f, 1.0f, 0.5f) * lit;  // a throughput after a green wall
    EXPECT_EQ(weighted.x, real(0));
    EXPECT_EQ(weighted.y, real(0));
    EXPECT_TRUE(std::isfinite(weighted.z));
}

TEST(PathTracer, OccludersCastShadowsGlassIncluded) {
    const Vec3 p(0.2f, 0.0f, 0.1f), light(0.2f, 3.0f, 0.1f);
    for (MaterialType type :
         {material_type<Diffuse>, material_type<Mirror>, material_type<Glass>}) {
        TestScene ts;
        ts.floor(ts.material(material_type<Diffuse>, Vec3(0.5f)));
        ts.sphere({0.2f, 1.5f, 0.1f}, 0.3f, ts.material(type, Vec3(0.9f)));
        ts.light(light, Vec3(4.0f));
        const SceneView v = ts.view();
        const Ray ray = ray_to({2, 1, 2}, p);  // sees p past the sphere
        ASSERT_NE(closest_hit(v, ray).kind, primitive_kind<Sphere>);
        expect_exact(trace_path(v, ray, kRng, 1), Vec3(0.0f));
        expect_exact(direct_light_from(v, p, {0, 1, 0}, Vec3(0.5f)), Vec3(0.0f));
    }
    // A sphere beside the segment, or beyond the light, casts no shadow on p.
    for (const Vec3 c : {Vec3(1.5f, 1.5f, 0.1f), Vec3(0.2f, 4.0f, 0.1f)}) {
        TestScene ts;
        ts.floor(ts.material(material_type<Diffuse>, Vec3(0.5f)));
        ts.sphere(c, 0.3f, ts.material(material_type<Diffuse>, Vec3(0.5f)));
        ts.light(light, Vec3(4.0f));
        expect_rel_near(direct_light_from(ts.view(), p, {0, 1, 0}, Vec3(0.5f)),
                        expected_direct(p, light, Vec3(4.0f), Vec3(0.5f)), 1e-5f);
    }
}

TEST(PathTracer, EscapingRaysReturnTheBackground) {
    TestScene ts;
    ts.scene.background = {0.1f, 0.2f, 0.3f};
    ts.light({0, 1, 0}, Vec3(100.0f));  // a point light is never seen directly
    const SceneView v = ts.view();
    for (int bounces : {1, 2, 8})
        expect_exact(trace_path(v, {{0, 0, 0}, {0, 0, -1}}, kRng, bounces), ts.scene.background);
    // With geometry, a ray that misses it.
    ts.floor(ts.material(material_type<Diffuse>, Vec3(0.5f)));
    expect_exact(trace_path(ts.view(), {{0, 1, 0}, {0, 1, 0}}, kRng, 4), ts.scene.background);
}

TEST(PathTracer, MirrorReflectsTheSky) {
    TestScene ts;
    const Vec3 tint(0.9f, 0.5f, 0.25f);
    ts.floor(ts.material(material_type<Mirror>, tint));
    ts.scene.background = {0.5f, 1.0f, 2.0f};
    ts.light({0, 3, 0}, Vec3(10.0f));  // mirrors take no light samples
    const SceneView v = ts.view();
    const Ray ray = ray_to({1, 1, 1}, {0.2f, 0, 0.1f});
    for (int bounces : {2, 3, 10})
        expect_exact(trace_path(v, ray, kRng, bounces), tint * ts.scene.background);
    // With one bounce the mirror is the last interaction: nothing comes back.
    expect_exact(trace_path(v, ray, kRng, 1), Vec3(0.0f));
}

TEST(PathTracer, MirrorShowsWhatItFaces) {
    // A mirror floor under a diffuse sphere: the reflected ray lands on the sphere's bottom,
    // which the light (above the sphere) cannot see: black. Beside it: the sky.
    TestScene ts;
    ts.floor(ts.material(material_type<Mirror>, Vec3(1.0f)),
             1e4f);  // wide: nothing escapes sideways
    ts.sphere({0, 2, 0}, 1.0f, ts.material(material_type<Diffuse>, Vec3(0.5f)));
    ts.light({0, 5, 0}, Vec3(10.0f));
    ts.scene.background = Vec3(0.25f);
    const SceneView v = ts.view();
    const Ray straight_down{{0.1f, 0.5f, 0}, {0, -1, 0}};  // under the sphere
    EXPECT_EQ(closest_hit(v, straight_down).kind, primitive_kind<Triangle>);
    const Vec3 l = trace_path(v, straight_down, kRng, 3);
    EXPECT_EQ(l.x, 0.0f);  // the sphere's unlit bottom; the next bounce would need > 3
}

TEST(PathTracer, DiffuseUnderUniformSkyIsAlbedoTimesSky) {
    // Every cosine-sampled ray from an infinite-ish floor escapes: each path gives exactly
    // albedo * background, whatever the random numbers.
    TestScene ts;
    const Vec3 albedo(0.2f, 0.5f, 0.75f);
    ts.floor(ts.material(material_type<Diffuse>, albedo), 1e4f);
    ts.scene.background = {1.0f, 0.5f, 0.25f};
    const SceneView v = ts.view();
    for (int s = 0; s < 200; ++s) {
        const Vec3 l = trace_path(v, ray_to({0, 1, 0}, {0.5f, 0, 0.5f}), SampleStream(1, 2, s), 4);
        ASSERT_FLOAT_EQ(l.x, albedo.x * 1.0f);
        ASSERT_FLOAT_EQ(l.y, albedo.y * 0.5f);
        ASSERT_FLOAT_EQ(l.z, albedo.z * 0.25f);
    }
}

TEST(PathTracer, GlassWhiteFurnace) {
    // Glass neither absorbs nor emits: under a uniform sky a path through a glass sphere
    // returns exactly the sky, or black only if it runs out of bounces.
    TestScene ts;
    ts.sphere({0, 0, -3}, 1.0f, ts.material(material_type<Glass>, Vec3(0.0f), 1.5f));
    ts.scene.background = Vec3(0.5f);
    const SceneView v = ts.view();
    int sky = 0, through = 0;
    const int n = 4000;
    for (int s = 0; s < n; ++s) {
        const SampleStream rng(3, 0, s);
        // Aim at a random point of the sphere's disc.
        const Vec3 target(rng.at(100) * 1.4f - 0.7f, rng.at(101) * 1.4f - 0.7f, -3.0f);
        const Ray ray = ray_to({0, 0, 0}, target);
        ASSERT_TRUE(closest_hit(v, ray).found());
        const Vec3 l = trace_path(v, ray, rng, 64);
        ASSERT_FALSE(std::isnan(l.x));
        ASSERT_TRUE(l.x == 0.0f || l.x == 0.5f) << l.x;
        sky += l.x == 0.5f;
        ++through;
    }
    EXPECT_EQ(through, n);
    EXPECT_GE(sky, n * 99 / 100);
}

TEST(PathTracer, GlassRefractsStraightThroughAtNormalIncidence) {
    // A ray along a diameter is never bent: behind the sphere it meets a lit diffuse floor
    // at the point straight ahead. With Fresnel reflection (4% per face) some paths go
    // back to the black sky; every other path sees exactly the floor's direct light.
    TestScene ts;
    const Vec3 albedo(0.5f);
    ts.floor(ts.material(material_type<Diffuse>, albedo));
    ts.sphere({0, 2, 0}, 0.5f, ts.material(material_type<Glass>, Vec3(0.0f), 1.5f));
    ts.light({3, 1, 0}, Vec3(2.0f));  // lights the floor under the sphere from the side
    const SceneView v = ts.view();
    const Vec3 expected = expected_direct({0, 0, 0}, {3, 1, 0}, Vec3(2.0f), albedo);
    int lit = 0, dark = 0;
    for (int s = 0; s < 1000; ++s) {
        const Vec3 l = trace_path(v, {{0, 4, 0}, {0, -1, 0}}, SampleStream(0, 0, s), 3);
        if (l.x == 0.0f) {
            ++dark;
        } else {
            ++lit;
            ASSERT_NEAR(l.x, expected.x, 1e-4f * expected.x);
        }
    }
    // Transmission through both faces: (1 - 0.04)^2 = 92%.
    EXPECT_NEAR(lit / 1000.0, 0.9216, 0.03);
    EXPECT_EQ(lit + dark, 1000);
}

TEST(PathTracer, RenderPixelDeterministicAndSeedDependent) {
    TestScene ts;
    ts.floor(ts.material(material_type<Diffuse>, Vec3(0.6f)));
    ts.sphere({0, 0.5f, 0}, 0.5f, ts.material(material_type<Diffuse>, Vec3(0.3f, 0.6f, 0.9f)));
    ts.light({1, 3, 1}, Vec3(5.0f));
    ts.scene.background = Vec3(0.1f);
    const SceneView v = ts.view();
    const Camera cam = Camera::look_at({0, 2, 4}, {0, 0.3f, 0}, {0, 1, 0}, 40.0f, 16, 16);
    RenderSettings rs;
    rs.width = 16;
    rs.height = 16;
    rs.spp = 8;
    rs.bounces = 4;
    rs.seed = 1;
    int differ = 0;
    for (int y = 0; y < 16; y += 3) {
        for (int x = 0; x < 16; x += 3) {
            const Vec3 a = render_pixel(v, cam, rs, x, y);
            const Vec3 b = render_pixel(v, cam, rs, x, y);
            ASSERT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z);
            ASSERT_TRUE(std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z));
            RenderSettings other = rs;
            other.seed = 2;
            const Vec3 c = render_pixel(v, cam, other, x, y);
            differ += (c.x != a.x || c.y != a.y || c.z != a.z);
        }
    }
    EXPECT_GE(differ, 30);  // of 36 pixels
}

TEST(PathTracer, RenderPixelAveragesOverThePixel) {
    // One 1x1 image, 90 degrees: the pixel spans [-1, 1]^2 on the plane z = -1. A black
    // card covers the left half of that view, the sky (1) the rest: the mean is 1/2.
    TestScene ts;
    const int black = ts.material(material_type<Diffuse>, Vec3(0.0f));
    const Vec3 a(-100, -100, -2), b(0, -100, -2), c(0, 100, -2), d(-100, 100, -2);
    ts.scene.of<Triangle>().push_back(make_triangle(a, b, c, black));
    ts.scene.of<Triangle>().push_back(make_triangle(a, c, d, black));
    ts.scene.background = Vec3(1.0f);
    const Camera cam = Camera::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 90.0f, 1, 1);
    RenderSettings rs;
    rs.width = rs.height = 1;
    rs.spp = 4096;
    rs.bounces = 2;
    const Vec3 l = render_pixel(ts.view(), cam, rs, 0, 0);
    EXPECT_NEAR(l.x, 0.5f, 0.03f);  // binomial sd 0.008
    // Every sample of a uniform view is the sky itself: the mean is exact.
    TestScene empty;
    empty.scene.background = {0.25f, 0.5f, 1.0f};
    rs.spp = 8;
    expect_exact(render_pixel(empty.view(), cam, rs, 0, 0), empty.scene.background);
}

// The Cornell box at 1e-4 and 1e5 times its size, with the light scaled by the square: the
// same random numbers must give the same radiance (no fixed epsilon anywhere).
TEST(PathTracer, ScaleInvariance) {
    const Scene base = load_scene(source_tree_path("common/scenes/cornell.json"));
    RenderSettings rs;
    rs.width = rs.height = 12;
    rs.spp = 16;
    rs.bounces = 4;
    const Camera base_cam = base.camera.for_image(rs.width, rs.height);
    for (float s : {1e-4f, 1e-2f, 1e3f, 1e5f}) {
        const Scene big = scaled(base, s);
        const Camera cam = big.camera.for_image(rs.width, rs.height);
        double sum_base = 0, sum_scaled = 0;
        int close = 0, pixels = 0;
        for (int y = 0; y < rs.height; ++y) {
            for (int x = 0; x < rs.width; ++x) {
                const Vec3 a = render_pixel(base.view(), base_cam, rs, x, y);
                const Vec3 b = render_pixel(big.view(), cam, rs, x, y);
                ASSERT_TRUE(std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z));
                sum_base += a.x + a.y + a.z;
                sum_scaled += b.x + b.y + b.z;
                const float diff = length(a - b), norm = length(a);
                close += diff <= 1e-3f * norm + 1e-12f;
                ++pixels;
            }
        }
        EXPECT_GT(sum_base, 0.0);
        EXPECT_NEAR(sum_scaled / sum_base, 1.0, 1e-2) << "scale " << s;
        EXPECT_GE(close, pixels * 9 / 10) << "scale " << s;
    }
}

// A closed room leaks no light: inside a cube of 12 triangles under a bright sky, every
// path must stay black. Camera rays aimed exactly at the cube's edges and corners (where two
// walls meet) must find a wall; whole paths in random directions must never escape.
TEST(PathTracer, ClosedBoxDoesNotLeak) {
    for (float scale : {1e-4f, 1.0f, 1e5f}) {
        for (const Vec3 offset : {Vec3(0.0f), Vec3(37.0f, -120.0f, 5.0f)}) {
            TestScene ts;
            const int wall = ts.material(material_type<Diffuse>, Vec3(0.9f));
            const int glass = ts.material(material_type<Glass>, Vec3(0.0f), 1.5f);
            const int mirror = ts.material(material_type<Mirror>, Vec3(1.0f));
            Vec3 corner[8];
            for (int i = 0; i < 8; ++i)
                corner[i] =
                    (Vec3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f) +
                     offset) *
                    scale;
            // Each face as a quad (v0 v1 v2 v3) split along v0-v2, facing inwards.
            const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                                     {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
            for (int f = 0; f < 6; ++f) {
                const int m = f == 1 ? mirror : wall;
                const int* q = faces[f];
                ts.scene.of<Triangle>().push_back(
                    make_triangle(corner[q[0]], corner[q[1]], corner[q[2]], m));
                ts.scene.of<Triangle>().push_back(
                    make_triangle(corner[q[0]], corner[q[2]], corner[q[3]], m));
            }
            ts.sphere((Vec3(0.3f, -0.4f, 0.2f) + offset) * scale, 0.3f * scale, glass);
            ts.scene.background = Vec3(1.0f);
            const SceneView v = ts.view();
            const Vec3 centre = (Vec3(-0.2f, 0.3f, -0.1f) + offset) * scale;
            int misses = 0, leaks = 0;
            for (int s = 0; s < 3000; ++s) {
                const SampleStream rng(0, 0, s);
                // A point on one of the 12 edges (from corner i0 along one axis), and a corner.
                const int e = s % 12, axis = e / 4, a = e & 1, b = (e >> 1) & 1;
                const int i0 = axis == 0   ? (a << 1) | (b << 2)
                               : axis == 1 ? a | (b << 2)
                                           : a | (b << 1);
                const Vec3 p0 = corner[i0], p1 = corner[i0 | (1 << axis)];
                for (const Vec3 target : {p0 + (p1 - p0) * rng.at(100), corner[s % 8]}) {
                    if (!closest_hit(v, {centre, normalize(target - centre)}).found()) ++misses;
                }
                // A whole path, starting in a uniformly random direction.
                const Vec3 d = sample_cosine_hemisphere(s % 2 ? Vec3(0, 0, 1) : Vec3(0, 0, -1),
                                                        rng.at(101), rng.at(102));
                const Vec3 l = trace_path(v, {centre, d}, rng, 12);
                ASSERT_FALSE(std::isnan(l.x));
                if (!is_black(l)) ++leaks;
            }
            EXPECT_EQ(misses, 0) << "scale " << scale << " offset " << offset.x;
            EXPECT_EQ(leaks, 0) << "scale " << scale << " offset " << offset.x;
        }
    }
}

// The same inside a diffuse sphere, with long paths: each bounce starts just inside the
// surface, so the hit point, the normal and the sampled direction must stay accurate bounce
// after bounce (errors must not compound).
TEST(PathTracer, SphereRoomDoesNotLeak) {
    for (float scale : {1e-4f, 1.0f, 1e3f, 1e5f}) {
        for (float radius : {0.5f, 2.0f, 50.0f}) {
            TestScene ts;
            const Vec3 centre = Vec3(3.0f, -2.0f, 1.0f) * scale;
            ts.sphere(centre, radius * scale, ts.material(material_type<Diffuse>, Vec3(0.9f)));
            ts.scene.background = Vec3(1.0f);
            const SceneView v = ts.view();
            int leaks = 0;
            for (int s = 0; s < 2000; ++s) {
                const SampleStream rng(1, 0, s);
                const Vec3 d = sample_cosine_hemisphere(s % 2 ? Vec3(1, 0, 0) : Vec3(-1, 0, 0),
                                                        rng.at(100), rng.at(101));
                const Vec3 origin = centre + Vec3(0.2f * radius * scale, 0.0f, 0.0f);
                if (!is_black(trace_path(v, {origin, d}, rng, 32))) ++leaks;
            }
            EXPECT_EQ(leaks, 0) << "scale " << scale << " radius " << radius;
        }
    }
}

// A sphere's shading normal is unit length even where the hit point is off the surface by
// rounding (the sampling basis and reflect() assume a unit normal).
TEST(PathTracer, SphereNormalIsUnitLength) {
    TestScene ts;
    ts.sphere({3, -2, 1}, 2.0f, ts.material(material_type<Diffuse>, Vec3(0.5f)));
    const SceneView v = ts.view();
    Hit hit;
    hit.kind = primitive_kind<Sphere>;
    hit.index = 0;
    // A ray whose t is a little off, as after a few bounces of rounding.
    for (float t : {2.0f, 2.0001f, 1.9999f}) {
        hit.t = t;
        const SurfacePoint sp = surface_at(v, {{3, -2, 1}, {1, 0, 0}}, hit);
        EXPECT_NEAR(length(sp.normal), 1.0f, 1e-6f) << "t " << t;
        EXPECT_GT(sp.normal.x, 0.99f);
    }
}

TEST(PathTracer, CornellPixelsAreFiniteAndPlausible) {
    const Scene scene = load_scene(source_tree_path("common/scenes/cornell.json"));
    RenderSettings rs;
    rs.width = rs.height = 8;
    rs.spp = 8;
    rs.bounces = 4;
    const Camera cam = scene.camera.for_image(rs.width, rs.height);
    int lit = 0;
    for (int y = 0; y < rs.height; ++y)
        for (int x = 0; x < rs.width; ++x) {
            const Vec3 l = render_pixel(scene.view(), cam, rs, x, y);
            ASSERT_TRUE(std::isfinite(l.x) && std::isfinite(l.y) && std::isfinite(l.z));
            ASSERT_GE(l.x, 0.0f);
            ASSERT_GE(l.y, 0.0f);
            ASSERT_GE(l.z, 0.0f);
            lit += max_component(l) > 0.0f;
        }
    EXPECT_GE(lit, 48);  // a closed box under a light: nearly every pixel gets something
}
