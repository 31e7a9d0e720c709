// Built with -DRT_DOUBLE only (make build/precision_tests_double, run by
// tests/labs/test_precision.py): the double build really computes in double. The first two
// tests ask for what float cannot give, so a switch that silently left the core in float
// fails them; the others check what only the double build uses (the triangle test's double
// fallback, the scene limits of double).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include <errors.h>
#include <scene_loader.h>
#include <axis_rect.h>
#include <convex_quad.h>
#include <sphere.h>
#include <triangle.h>

TEST(DoubleBuild, RealIsDouble) {
    EXPECT_EQ(sizeof(real), sizeof(double));
    EXPECT_EQ(sizeof(Vec3), 3 * sizeof(double));
    EXPECT_STREQ(kPrecisionName, "double");
}

// A unit sphere 1e8 from the origin, seen from 10 units away: floats there are 8 apart, so a
// float intersection cannot even place the ray's origin. Double gives t to ~1e-8.
TEST(DoubleBuild, ResolvesASphereFarFromTheOrigin) {
    const double far = 1e8;
    const Sphere s{Vec3(far, 0, 0), 1.0, 0};
    const Ray ray{Vec3(far - 10, 0.5, 0), Vec3(1, 0, 0)};
    const double expected = 10 - std::sqrt(1 - 0.25);
    EXPECT_NEAR(intersect_sphere(ray, s, kRealMax), expected, 1e-7);
}

// The watertight test's fallback in double: two products that round to the same double
// (the fast edge function says 0) but differ exactly by 2^-60. The fallback finds the sign,
// and the edge seen from the other side gets exactly the negated value.
TEST(DoubleBuild, EdgeFunctionFallbackFindsTheSignOfADifferenceBelowRounding) {
    const double px = 1 + std::ldexp(1.0, -30), qy = 1 + std::ldexp(1.0, -30);  // 1 + 2^-29 + 2^-60
    const double py = 1 + std::ldexp(1.0, -29), qx = 1;  // 1 + 2^-29
    EXPECT_EQ(edge_function(px, py, qx, qy), 0.0);
    const double exact = edge_function_exact(px, py, qx, qy);
    EXPECT_EQ(exact, std::ldexp(1.0, -60));
    EXPECT_EQ(edge_function_exact(qx, qy, px, py), -exact);
}

// A ray through the edge two triangles share hits at least one of them, with coordinates
// whose float roundings would move the edge.
TEST(DoubleBuild, SharedEdgeStaysWatertight) {
    const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0), d(1, 1, 0);
    const Triangle t1 = make_triangle(a, b, d, 0);
    const Triangle t2 = make_triangle(a, d, c, 0);
    for (int i = 1; i < 1000; ++i) {
        const double x = i / 1000.0 + 1e-12;  // on the diagonal a-d, off float's grid
        const Ray ray{Vec3(x, x, 1), Vec3(0, 0, -1)};
        const RayShear shear(ray.direction);
        const bool hit = intersect_triangle(ray, shear, t1, kRealMax) < kRealMax ||
                         intersect_triangle(ray, shear, t2, kRealMax) < kRealMax;
        EXPECT_TRUE(hit) << "x = " << x;
    }
}

// The same for two convex quads and two rectangles that share an edge off float's grid: the
// quads' edge functions take the double fallback, the rectangles' canonical ones are doubles.
TEST(DoubleBuild, SharedEdgesOfQuadsAndRectanglesStayWatertight) {
    const double e = 0.5 + 1e-12;  // the shared edge x = e, which float would move
    const ConvexQuad left =
        make_convex_quad(Vec3(0, 0, 0), Vec3(e, 0, 0), Vec3(e, 1, 0), Vec3(0, 1, 0), 0);
    const ConvexQuad right =
        make_convex_quad(Vec3(e, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(e, 1, 0), 0);
    const Vec3 l[4] = {Vec3(0, 0, 0), Vec3(e, 0, 0), Vec3(e, 1, 0), Vec3(0, 1, 0)};
    const Vec3 r[4] = {Vec3(e, 0, 0), Vec3(1, 0, 0), Vec3(1, 1, 0), Vec3(e, 1, 0)};
    ASSERT_EQ(axis_rect_axis(l), 2);
    const AxisRect rect_l = make_axis_rect(l, 2, 0), rect_r = make_axis_rect(r, 2, 0);
    EXPECT_EQ(rect_l.hi_u, e);
    for (int i = 1; i < 1000; ++i) {
        const double y = i / 1000.0;
        for (double dx : {-0.3, 0.0, 0.7}) {
            const Vec3 target(e, y, 0), origin(e + dx, y + 0.1, 1);
            const Ray ray{origin, normalize(target - origin)};
            const RayShear shear(ray.direction);
            EXPECT_TRUE(intersect_quad(ray, shear, left, kRealMax) < kRealMax ||
                        intersect_quad(ray, shear, right, kRealMax) < kRealMax)
                << "y = " << y;
            EXPECT_TRUE(intersect_rect(ray, rect_l, kRealMax) < kRealMax ||
                        intersect_rect(ray, rect_r, kRealMax) < kRealMax)
                << "y = " << y;
        }
    }
}

// The scene loader's limits are double's (scene_limits.h): a sphere of radius 1e12, past
// float's 1e9, loads; one past 1e30 is refused in one line that names double's bound.
TEST(DoubleBuild, SceneLimitsAreDoubles) {
    const auto scene = [](const char* radius) {
        return std::string(
                   "{ \"camera\": { \"position\": [0, 0, 0], \"look_at\": [0, 0, -1] },\n"
                   "  \"materials\": { \"m\": { \"type\": \"diffuse\",\n"
                   "                          \"albedo\": [0.5, 0.5, 0.5] } },\n"
                   "  \"spheres\": [ { \"center\": [0, 0, 0], \"radius\": ") +
               radius + ", \"material\": \"m\" } ] }\n";
    };
    EXPECT_NO_THROW(parse_scene(scene("1e12"), "wide.json"));
    try {
        parse_scene(scene("1e31"), "too-wide.json");
        FAIL() << "a radius of 1e31 was accepted";
    } catch (const InputError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
        EXPECT_NE(message.find("above 1e30"), std::string::npos) << message;
        EXPECT_NE(message.find("double"), std::string::npos) << message;
    }
}
