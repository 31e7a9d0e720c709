// Watertight ray/triangle intersection: front and back hits, misses, parallel and grazing
// rays, degenerate triangles, shared edges and vertices at every scale, and no
// self-intersection after offset_ray_origin.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>
#include <vector>

#include "ray.h"
#include "triangle.h"

namespace {

float hit(const Ray& ray, const Triangle& tri, float t_max = FLT_MAX) {
    return intersect_triangle(ray, RayShear(ray.direction), tri, t_max);
}

Vec3 random_unit(std::mt19937& gen) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (;;) {
        const Vec3 v(n(gen), n(gen), n(gen));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

// Distance along the ray to the triangle's plane, in double (no inside test).
double plane_t(const Ray& ray, const Triangle& tri) {
    const double e1x = double(tri.v1.x) - tri.v0.x, e1y = double(tri.v1.y) - tri.v0.y,
                 e1z = double(tri.v1.z) - tri.v0.z;
    const double e2x = double(tri.v2.x) - tri.v0.x, e2y = double(tri.v2.y) - tri.v0.y,
                 e2z = double(tri.v2.z) - tri.v0.z;
    const double nx = e1y * e2z - e1z * e2y, ny = e1z * e2x - e1x * e2z, nz = e1x * e2y - e1y * e2x;
    const double num = nx * (double(tri.v0.x) - ray.origin.x) +
                       ny * (double(tri.v0.y) - ray.origin.y) +
                       nz * (double(tri.v0.z) - ray.origin.z);
    const double den = nx * ray.direction.x + ny * ray.direction.y + nz * ray.direction.z;
    return num / den;
}

// Builds the unit quad's two triangles (shared diagonal v0-v2), scaled and moved.
struct Quad {
    Vec3 p[4];
    Triangle a, b;
    Vec3 normal_dir;  // unit normal of the (planar) quad, unscaled
};
Quad make_quad(float scale, Vec3 offset, Vec3 tilt) {
    Quad q;
    const Vec3 corners[4] = {
        {0, 0, 0}, {1, 0.1f, 0}, {1.1f, 1, 0}, {-0.1f, 0.9f, 0}};  // planar, convex
    for (int i = 0; i < 4; ++i) {
        const Vec3 c = corners[i];
        q.p[i] = (Vec3(c.x, c.y, c.z + tilt.x * c.x + tilt.y * c.y) + offset) * scale;
    }
    q.normal_dir = normalize(Vec3(-tilt.x, -tilt.y, 1.0f));
    q.a = make_triangle(q.p[0], q.p[1], q.p[2], 0);
    q.b = make_triangle(q.p[0], q.p[2], q.p[3], 0);
    return q;
}

}  // namespace

TEST(Triangle, MakeTriangleNormalFollowsWinding) {
    const Triangle t = make_triangle({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, 5);
    EXPECT_EQ(t.material, 5);
    EXPECT_FLOAT_EQ(t.normal.x, 0.0f);
    EXPECT_FLOAT_EQ(t.normal.y, 0.0f);
    EXPECT_FLOAT_EQ(t.normal.z, 1.0f);
    const Triangle r = make_triangle({0, 0, 0}, {0, 3, 0}, {2, 0, 0}, 0);
    EXPECT_FLOAT_EQ(r.normal.z, -1.0f);
}

TEST(Triangle, FrontAndBackHits) {
    const Triangle tri = make_triangle({-1, -1, -2}, {1, -1, -2}, {0, 1, -2}, 0);
    const Ray front{{0, 0, 0}, {0, 0, -1}};   // from the side the normal points to
    const Ray back{{0, 0, -5}, {0, 0, 1}};    // from behind
    EXPECT_FLOAT_EQ(hit(front, tri), 2.0f);
    EXPECT_FLOAT_EQ(hit(back, tri), 3.0f);
    // Every dominant axis and sign: rotate the setup through the axes.
    for (int axis = 0; axis < 3; ++axis) {
        for (float sign : {1.0f, -1.0f}) {
            auto perm = [&](float along, float a, float b) {
                Vec3 v;
                float c[3];
                c[axis] = along;
                c[(axis + 1) % 3] = a;
                c[(axis + 2) % 3] = b;
                v = {c[0], c[1], c[2]};
                return v;
            };
            const Triangle t = make_triangle(perm(3 * sign, -1, -1), perm(3 * sign, 1, -1),
                                             perm(3 * sign, 0, 1), 0);
            const Ray ray{perm(0, 0.1f, -0.2f), perm(sign, 0, 0)};
            EXPECT_FLOAT_EQ(hit(ray, t), 3.0f) << "axis " << axis << " sign " << sign;
            const Ray away{perm(0, 0.1f, -0.2f), perm(-sign, 0, 0)};
            EXPECT_EQ(hit(away, t), FLT_MAX) << "axis " << axis << " sign " << sign;
        }
    }
}

TEST(Triangle, Misses) {
    const Triangle tri = make_triangle({-1, -1, -2}, {1, -1, -2}, {0, 1, -2}, 0);
    EXPECT_EQ(hit({{2, 0, 0}, {0, 0, -1}}, tri), FLT_MAX);       // beside
    EXPECT_EQ(hit({{0, 1.01f, 0}, {0, 0, -1}}, tri), FLT_MAX);   // just above the apex
    EXPECT_EQ(hit({{0, 0, -3}, {0, 0, -1}}, tri), FLT_MAX);      // behind the origin
    EXPECT_EQ(hit({{0, 0, 0}, {0, 0, -1}}, tri, 1.99f), 1.99f);  // beyond t_max
    EXPECT_EQ(hit({{0, 0, 0}, {0, 0, -1}}, tri, 2.0f), 2.0f);    // open interval
    EXPECT_FLOAT_EQ(hit({{0, 0, 0}, {0, 0, -1}}, tri, 2.01f), 2.0f);
}

// Random rays against a double-precision reference, at unit scale and at the extremes
// (1e-4, 1e5), with the triangle away from the world origin.
TEST(Triangle, RandomRaysMatchDoubleReference) {
    std::mt19937 gen(5);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    std::uniform_real_distribution<float> bary(-0.2f, 1.2f);
    for (float scale : {1e-4f, 1.0f, 1e5f}) {
        const Vec3 offset(3.0f, -2.0f, 5.0f);
        const Triangle tri = make_triangle((Vec3(0.1f, -0.3f, 0.2f) + offset) * scale,
                                           (Vec3(1.2f, 0.4f, -0.5f) + offset) * scale,
                                           (Vec3(-0.4f, 1.1f, 0.3f) + offset) * scale, 0);
        int hits = 0;
        for (int i = 0; i < 20000; ++i) {
            // Aim at a random barycentric point (inside or a little outside).
            const float b1 = bary(gen), b2 = bary(gen);
            const Vec3 target = tri.v0 + (tri.v1 - tri.v0) * b1 + (tri.v2 - tri.v0) * b2;
            const Vec3 origin = (offset + Vec3(u(gen), u(gen), u(gen))) * scale;
            const Ray ray{origin, normalize(target - origin)};
            const float t = hit(ray, tri);
            ASSERT_FALSE(std::isnan(t));
            const bool clearly_inside = b1 > 1e-3f && b2 > 1e-3f && b1 + b2 < 1 - 1e-3f;
            const bool clearly_outside = b1 < -1e-3f || b2 < -1e-3f || b1 + b2 > 1 + 1e-3f;
            const double ref = plane_t(ray, tri);
            if (clearly_inside && ref > 1e-3 * scale) {
                ++hits;
                ASSERT_LT(t, FLT_MAX) << "scale " << scale << " ray " << i;
                // The hit point's distance from the plane is what t's error amounts to:
                // compare that, so that grazing rays (ill-conditioned t) are judged fairly.
                const double cos_angle = std::fabs(dot(ray.direction, tri.normal));
                ASSERT_LT(std::fabs(t - ref) * cos_angle, 2e-6 * (8.0 * scale + ref))
                    << "scale " << scale << " ray " << i;
                // Along the ray, t is the plane's distance (num / denom): its error grows as
                // 1/cos for grazing rays, which slides the hit point along the surface, not
                // off it (the bound above). Rays steeper than 6 degrees: within 1e-4.
                if (cos_angle > 0.1) {
                    ASSERT_LT(std::fabs(t - ref), 1e-4 * ref) << "scale " << scale << " ray " << i;
                }
            } else if (clearly_outside) {
                ASSERT_EQ(t, FLT_MAX) << "scale " << scale << " ray " << i;
            }
        }
        EXPECT_GT(hits, 3000) << "scale " << scale;
    }
}

TEST(Triangle, ParallelRaysInThePlaneMiss) {
    const Triangle tri = make_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    // Origin in the plane, directions in the plane: through the triangle's interior.
    const Ray rays[] = {
        {{-1, 0.2f, 0}, {1, 0, 0}},
        {{0.2f, -1, 0}, {0, 1, 0}},
        {{-1, -1, 0}, normalize(Vec3(1, 1, 0))},
        {{-1, 0.2f, 0.5f}, {1, 0, 0}},  // above the plane, parallel
        {{-0.3f, -0.4f, 0}, {0.6f, 0.8f, 0}},
    };
    for (const Ray& ray : rays) {
        const float t = hit(ray, tri);
        EXPECT_FALSE(std::isnan(t));
        EXPECT_EQ(t, FLT_MAX) << ray.origin.x << " " << ray.origin.y << " " << ray.origin.z;
    }
}

TEST(Triangle, NearlyParallelRaysNeverGiveNaN) {
    std::mt19937 gen(9);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const Triangle tri =
        make_triangle({0.1f, -0.3f, 0.2f}, {1.2f, 0.4f, -0.5f}, {-0.4f, 1.1f, 0.3f}, 0);
    Vec3 e1, e2;
    orthonormal_basis(tri.normal, e1, e2);
    for (int i = 0; i < 20000; ++i) {
        // Origin on (or within rounding of) the plane, direction in it, tilted by <= 1e-6.
        const Vec3 origin = tri.v0 + (tri.v1 - tri.v0) * u(gen) + (tri.v2 - tri.v0) * u(gen);
        const Vec3 d = normalize(e1 * u(gen) + e2 * u(gen) + tri.normal * (1e-6f * u(gen)));
        const float t = hit({origin, d}, tri);
        ASSERT_FALSE(std::isnan(t)) << "ray " << i;
        ASSERT_GT(t, 0.0f);
    }
}

TEST(Triangle, GrazingRaysHitAccurately) {
    // A triangle in z = 0 and rays that come in at 1e-3 rad, hitting its interior.
    const Triangle tri = make_triangle({0, 0, 0}, {10, 0, 0}, {0, 10, 0}, 0);
    std::mt19937 gen(2);
    std::uniform_real_distribution<float> u(0.5f, 4.0f);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 target(u(gen), u(gen), 0.0f);
        const float angle = 1e-3f;
        const Vec3 d = normalize(Vec3(std::cos(angle), 0.0f, -std::sin(angle)));
        const Ray ray{target - d * 3.0f, d};
        const double ref = plane_t(ray, tri);
        const float t = hit(ray, tri);
        ASSERT_LT(t, FLT_MAX) << "ray " << i;
        // A grazing ray's t is ill-conditioned: the plane distance error is amplified by
        // 1/sin(angle), so compare the hit point's height above the plane instead.
        EXPECT_NEAR(t, ref, 1e-3);
        EXPECT_NEAR(ray.at(t).z, 0.0f, 1e-5f);
    }
}

TEST(Triangle, DegenerateTrianglesHaveZeroNormalAndNeverHit) {
    std::mt19937 gen(4);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    const Triangle degenerate[] = {
        make_triangle({0, 0, 0}, {0, 0, 0}, {1, 1, 0}, 0),  // repeated vertex
        make_triangle({1, 2, 3}, {1, 2, 3}, {1, 2, 3}, 0),  // a point
        make_triangle({0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 0),  // collinear
        make_triangle({0.125f, 0.25f, 0.3f}, {0.875f, 0.75f, 0.3f}, {0.5f, 0.5f, 0.3f},
                      0),  // collinear
        make_triangle({-1, 0.5f, 0}, {3, 0.5f, 0}, {1, 0.5f, 0}, 0),  // collinear, middle last
    };
    for (const Triangle& tri : degenerate) {
        EXPECT_TRUE(is_black(tri.normal))
            << tri.v2.x << " " << tri.normal.x << " " << tri.normal.y << " " << tri.normal.z;
        int hits = 0;
        for (int i = 0; i < 20000; ++i) {
            // Rays aimed at points on the segment (where a hit would be reported, if at all).
            std::uniform_real_distribution<float> s(0.0f, 1.0f);
            const float a = s(gen), b = s(gen) * (1 - a);
            const Vec3 target = tri.v0 + (tri.v1 - tri.v0) * a + (tri.v2 - tri.v0) * b;
            const Vec3 origin(u(gen), u(gen), u(gen));
            const float t = hit({origin, normalize(target - origin)}, tri);
            ASSERT_FALSE(std::isnan(t));
            if (t < FLT_MAX) ++hits;
        }
        EXPECT_EQ(hits, 0) << "degenerate triangle (" << tri.v0.x << "," << tri.v0.y << ","
                           << tri.v0.z << ") (" << tri.v1.x << "," << tri.v1.y << "," << tri.v1.z
                           << ") (" << tri.v2.x << "," << tri.v2.y << "," << tri.v2.z << ")";
    }
}

// Random exactly collinear triangles (coordinates on a 1/8 grid, so the float arithmetic is
// exact): zero normal, and rays aimed along them never hit.
TEST(Triangle, RandomCollinearTrianglesNeverHit) {
    std::mt19937 gen(8);
    std::uniform_int_distribution<int> grid(-16, 16);
    std::uniform_int_distribution<int> step(-3, 3);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f), u01(0.0f, 1.0f);
    int hits = 0, triangles = 0;
    for (int k = 0; k < 400; ++k) {
        const Vec3 a(grid(gen) / 8.0f, grid(gen) / 8.0f, grid(gen) / 8.0f);
        const Vec3 e(grid(gen) / 8.0f, grid(gen) / 8.0f, grid(gen) / 8.0f);
        const Triangle tri =
            make_triangle(a, a + e * float(step(gen)), a + e * float(step(gen)), 0);
        ASSERT_TRUE(is_black(tri.normal));
        ++triangles;
        for (int i = 0; i < 100; ++i) {
            const Vec3 target = a + e * (u(gen));
            const Vec3 origin(u(gen), u(gen), u(gen));
            const float t = hit({origin, normalize(target - origin)}, tri);
            ASSERT_FALSE(std::isnan(t));
            if (t < FLT_MAX) ++hits;
        }
    }
    EXPECT_EQ(triangles, 400);
    EXPECT_EQ(hits, 0);
}

// Rays aimed exactly at (the float rounding of) points on a shared edge: at least one of the
// two triangles must report the hit, at every scale.
TEST(Triangle, WatertightSharedDiagonal) {
    std::mt19937 gen(1234);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_real_distribution<float> along(0.02f, 0.98f);
    struct Case {
        float scale;
        Vec3 offset;
        Vec3 tilt;
    };
    const Case cases[] = {
        {1.0f, {0, 0, 0}, {0, 0, 0}},
        {1.0f, {0.3f, -0.7f, 2.0f}, {0.3f, -0.5f, 0}},
        {1e-4f, {0.3f, -0.7f, 2.0f}, {0.3f, -0.5f, 0}},
        {1e5f, {0.3f, -0.7f, 2.0f}, {0.3f, -0.5f, 0}},
        {1e-4f, {100, 0, 0}, {1, 1, 0}},
        {1e5f, {0, 0, -30}, {-2, 0.5f, 0}},
    };
    long total = 0;
    for (const Case& c : cases) {
        const Quad q = make_quad(c.scale, c.offset, c.tilt);
        int leaks = 0;
        const int n = 20000;
        for (int i = 0; i < n; ++i) {
            const float s = along(gen);
            // On the diagonal p0 -> p2; several ways to compute a point "on" it.
            Vec3 target;
            switch (i % 3) {
                case 0: target = q.p[0] + (q.p[2] - q.p[0]) * s; break;
                case 1: target = q.p[0] * (1 - s) + q.p[2] * s; break;
                default: target = q.p[2] + (q.p[0] - q.p[2]) * s; break;
            }
            // Origins on either side, at least 0.2 away from the plane.
            const float height = (0.2f + std::fabs(u(gen)) * 2.8f) * (i % 2 ? 1.0f : -1.0f);
            Vec3 e1, e2;
            orthonormal_basis(q.normal_dir, e1, e2);
            const Vec3 centre = (q.p[0] + q.p[2]) * 0.5f;
            const Vec3 origin =
                centre + (q.normal_dir * height + (e1 * u(gen) + e2 * u(gen)) * 3.0f) * c.scale;
            const Ray ray{origin, normalize(target - origin)};
            const RayShear shear(ray.direction);
            const float ta = intersect_triangle(ray, shear, q.a, FLT_MAX);
            const float tb = intersect_triangle(ray, shear, q.b, FLT_MAX);
            ASSERT_FALSE(std::isnan(ta) || std::isnan(tb));
            if (ta == FLT_MAX && tb == FLT_MAX) ++leaks;
            ++total;
        }
        EXPECT_EQ(leaks, 0) << "scale " << c.scale << " offset " << c.offset.x;
    }
    EXPECT_EQ(total, 6 * 20000);
}

// A fan of triangles around a centre vertex (planar, and bent into a shallow cone): rays
// aimed at the centre and at points on the spokes always hit some triangle.
TEST(Triangle, WatertightFanAroundVertex) {
    std::mt19937 gen(77);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    for (float scale : {1e-4f, 1.0f, 1e5f}) {
        for (float lift : {0.0f, 0.3f}) {
            const Vec3 centre = Vec3(0.3f, 0.2f, -1.7f) * scale;
            const int k = 7;
            std::vector<Vec3> rim;
            for (int i = 0; i < k; ++i) {
                const float phi = 2.0f * 3.14159265f * (i + 0.3f * u01(gen)) / k;
                rim.push_back(centre + Vec3(std::cos(phi), std::sin(phi), lift) * scale);
            }
            std::vector<Triangle> fan;
            for (int i = 0; i < k; ++i)
                fan.push_back(make_triangle(centre, rim[i], rim[(i + 1) % k], 0));
            int leaks = 0;
            for (int i = 0; i < 20000; ++i) {
                // Origins above, within 35 degrees of the axis, so that the (possibly bent)
                // fan projects onto a neighbourhood of the centre without folding over.
                const Vec3 origin = centre + Vec3(u(gen), u(gen), 2.0f + u01(gen)) * scale;
                Vec3 target = centre;
                if (i % 2 == 1) {  // a point on a spoke, shared by two triangles
                    const Vec3 rim_point = rim[i % k];
                    target = centre + (rim_point - centre) * (0.9f * u01(gen));
                }
                const Ray ray{origin, normalize(target - origin)};
                const RayShear shear(ray.direction);
                bool any = false;
                for (const Triangle& tri : fan)
                    any = any || intersect_triangle(ray, shear, tri, FLT_MAX) < FLT_MAX;
                if (!any) ++leaks;
            }
            EXPECT_EQ(leaks, 0) << "scale " << scale << " lift " << lift;
        }
    }
}

// The needles of a fan (10,000 triangles around a disk's centre, aspect 1,600), hit by rays
// from a point above the disk and off its centre: every hit point lies within the ray offset
// of the disk's plane (ray.h), so the next ray, offset toward the ray's side, starts in front
// of the disk. Woop's barycentric distance put hit points several offsets off the plane here
// (some under the surface, whose shadow rays then hit the disk: tests/labs/test_extremes.py);
// the plane's distance, which intersect_triangle returns, keeps them well within one.
TEST(Triangle, NeedleHitsStayWithinTheOffset) {
    const int count = 10000;
    const float radius = 8.0f;
    std::mt19937 gen(12);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    auto rim = [&](int k) {
        const double phi = 2.0 * 3.14159265358979 * (k % count) / count;
        return Vec3(float(radius * std::cos(phi)), 0.0f, float(radius * std::sin(phi)));
    };
    int hits = 0;
    double worst = 0.0;
    for (int i = 0; i < 20000; ++i) {
        const int k = int(u01(gen) * count) % count;
        const Triangle needle = make_triangle(Vec3(0.0f), rim(k + 1), rim(k), 0);
        float a = u01(gen), b = u01(gen);  // a point inside, clear of the edges
        if (a + b > 1) {
            a = 1 - a;
            b = 1 - b;
        }
        a = 0.02f + 0.96f * a;
        b = 0.02f + 0.96f * b * (1 - a);
        const Vec3 target = needle.v0 + (needle.v1 - needle.v0) * a + (needle.v2 - needle.v0) * b;
        const Vec3 origin(0.3f * u01(gen), 1.0f, 0.3f * u01(gen));
        const Ray ray{origin, normalize(target - origin)};
        const float t = hit(ray, needle);
        if (t == FLT_MAX) continue;  // rounding at an edge: the neighbour takes the ray
        ++hits;
        const Vec3 p = ray.at(t);
        worst = std::max(worst, std::fabs(double(p.y)) / ray_offset(p, t, needle.extent));
    }
    EXPECT_GT(hits, 19000);
    EXPECT_LT(worst, 0.5) << "a hit point lies " << worst << " ray offsets off the plane";
}

// A ray leaving a triangle from offset_ray_origin does not hit that triangle again, whether
// it leaves on the normal side or the back side, at every scale.
TEST(Triangle, NoSelfIntersectionAfterOffset) {
    std::mt19937 gen(31);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    for (float scale : {1e-4f, 1e-2f, 1.0f, 1e3f, 1e5f}) {
        for (const Vec3 offset : {Vec3(0.0f), Vec3(5, -3, 2), Vec3(0, 0, -800)}) {
            const Triangle tri = make_triangle((Vec3(0, 0, 0) + offset) * scale,
                                               (Vec3(1, 0.2f, 0.1f) + offset) * scale,
                                               (Vec3(0.2f, 1, -0.3f) + offset) * scale, 0);
            int hits = 0;
            for (int i = 0; i < 5000; ++i) {
                float a = u01(gen), b = u01(gen);
                if (a + b > 1) {
                    a = 1 - a;
                    b = 1 - b;
                }
                const Vec3 p = tri.v0 + (tri.v1 - tri.v0) * a + (tri.v2 - tri.v0) * b;
                const Vec3 side = (i % 2) ? tri.normal : -tri.normal;
                Vec3 d;
                do {
                    d = random_unit(gen);
                } while (dot(d, side) < 0.02f);
                const Ray ray{offset_ray_origin(p, side, u01(gen) * scale, tri.extent), d};
                if (hit(ray, tri) < FLT_MAX) ++hits;
            }
            EXPECT_EQ(hits, 0) << "scale " << scale << " offset " << offset.z;
        }
    }
}

// A plane the ray reaches only after t_max, or one exactly at t_max, is culled; one just
// before t_max is not, whatever the sign of the triangle's normal.
TEST(Triangle, CullKeepsHitsJustBeforeTMax) {
    const Triangle front = make_triangle({-1, -1, -2}, {1, -1, -2}, {0, 1, -2}, 0);
    const Triangle back = make_triangle({-1, -1, -2}, {0, 1, -2}, {1, -1, -2}, 0);
    const Ray ray{{0, 0, 0}, {0, 0, -1}};
    for (const Triangle& tri : {front, back}) {
        EXPECT_EQ(hit(ray, tri, 2.0001f), 2.0f);
        EXPECT_EQ(hit(ray, tri, 2.0f), 2.0f);  // exactly at t_max: a miss, reported as t_max
        EXPECT_EQ(hit(ray, tri, 1.9f), 1.9f);
        EXPECT_EQ(hit({{0, 0, -3}, {0, 0, -1}}, tri, 10.0f), 10.0f);  // plane behind the ray
    }
}
