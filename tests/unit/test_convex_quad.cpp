// Planar convex quads (convex_quad.h): hits agree with the quad's two triangles, rays through
// an edge shared with another quad or a triangle never miss both, guards fail on NaN, rays
// parallel to the plane and quads with no area miss, classification, and edge steps.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>

#include "convex_quad.h"

namespace {

float hit(const Ray& ray, const ConvexQuad& q, float t_max = FLT_MAX) {
    return intersect_quad(ray, RayShear(ray.direction), q, t_max);
}
float hit(const Ray& ray, const Triangle& t, float t_max = FLT_MAX) {
    return intersect_triangle(ray, RayShear(ray.direction), t, t_max);
}

Vec3 random_unit(std::mt19937& gen) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (;;) {
        const Vec3 v(n(gen), n(gen), n(gen));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

// A tilted parallelogram and its neighbour across the edge v1v2, bent by 30 degrees: the
// neighbour's edge v3v0 is the first one's v1v2 reversed, the same floats.
struct QuadPair {
    Vec3 p[6];  // p0 p1 p2 p3 of the first; the second is p1 p4 p5 p2
    ConvexQuad first, second;
};
QuadPair make_pair_of_quads(float scale, Vec3 offset) {
    QuadPair q;
    const Vec3 u = Vec3(1.0f, 0.2f, 0.1f) * scale, v = Vec3(0.3f, 1.1f, -0.2f) * scale;
    const Vec3 w = Vec3(0.9f, 0.1f, 0.6f) * scale;
    q.p[0] = offset;
    q.p[1] = offset + u;
    q.p[2] = offset + u + v;
    q.p[3] = offset + v;
    q.p[4] = q.p[1] + w;
    q.p[5] = q.p[2] + w;
    q.first = make_convex_quad(q.p[0], q.p[1], q.p[2], q.p[3], 0);
    q.second = make_convex_quad(q.p[1], q.p[4], q.p[5], q.p[2], 0);
    return q;
}

// A point of segment a-b, rounded: exactly on the edge or beside it by rounding. (Not its
// ends: at a vertex only the faces all around it together are watertight.)
Vec3 on_segment(Vec3 a, Vec3 b, float s) { return a + (b - a) * s; }

}  // namespace

TEST(ConvexQuad, LayoutIsFiveRowsWithEachVertexStartingARow) {
    EXPECT_EQ(alignof(ConvexQuad), 16u);
    EXPECT_EQ(sizeof(ConvexQuad), 5 * 4 * sizeof(real));
    EXPECT_EQ(offsetof(ConvexQuad, v0) % 16, 0u);
    EXPECT_EQ(offsetof(ConvexQuad, v3) % 16, 0u);
}

TEST(ConvexQuad, HitsWhereItsTwoTrianglesDoAtTheirDistance) {
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> uni(-1.0f, 2.0f);
    const QuadPair q = make_pair_of_quads(1.0f, {0.2f, -0.3f, 0.1f});
    const Triangle a = make_triangle(q.p[0], q.p[1], q.p[2], 0);
    const Triangle b = make_triangle(q.p[0], q.p[2], q.p[3], 0);
    int hits = 0;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 target(uni(gen), uni(gen), uni(gen) * 0.2f);
        const Vec3 origin = target + random_unit(gen) * 5.0f;
        const Ray ray{origin, normalize(target - origin)};
        const float tq = hit(ray, q.first);
        const float tt = std::fmin(hit(ray, a), hit(ray, b));
        ASSERT_EQ(tq < FLT_MAX, tt < FLT_MAX) << i;  // no ray lands within rounding of an edge
        if (tq < FLT_MAX) {
            ++hits;
            EXPECT_NEAR(tq, tt, 1e-5f * tt);
        }
    }
    EXPECT_GT(hits, 2000);
}

// Origins in front of both faces of a fold (its outside), so that the two faces project onto
// either side of the shared edge: every ray aimed at the edge meets one of them. (From behind
// one face the two overlap in projection, and a ray may pass beside the fold.)
bool in_front_of_both(Vec3 origin, Vec3 on_edge, Vec3 n1, Vec3 n2, float margin) {
    return dot(origin - on_edge, n1) > margin && dot(origin - on_edge, n2) > margin;
}

TEST(ConvexQuad, RaysThroughASharedEdgeOrVertexNeverMissBothQuads) {
    std::mt19937 gen(7);
    std::uniform_real_distribution<float> s(0.0f, 1.0f);
    for (float scale : {1e-3f, 1.0f, 1e4f}) {
        for (Vec3 offset : {Vec3(0.0f), Vec3(123.456f, -78.9f, 4.2f) * scale}) {
            const QuadPair q = make_pair_of_quads(scale, offset);
            int tested = 0;
            for (int i = 0; i < 40000; ++i) {
                const Vec3 target = on_segment(q.p[1], q.p[2], s(gen));
                const Vec3 origin = target + random_unit(gen) * (3.0f * scale);
                if (!in_front_of_both(origin, q.p[1], q.first.normal, q.second.normal,
                                      0.2f * scale))
                    continue;
                const Ray ray{origin, normalize(target - origin)};
                ++tested;
                const bool either = hit(ray, q.first) < FLT_MAX || hit(ray, q.second) < FLT_MAX;
                ASSERT_TRUE(either) << "scale " << scale << " ray " << i;
            }
            EXPECT_GT(tested, 4000);
        }
    }
}

TEST(ConvexQuad, RaysThroughAnEdgeSharedWithATriangleNeverMissBoth) {
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> s(0.0f, 1.0f);
    const QuadPair q = make_pair_of_quads(1.0f, {0.37f, 0.11f, -0.29f});
    // The second quad as two triangles instead: the first quad's edge p1p2 is the triangle
    // p1 p5 p2's edge p2p1.
    const Triangle t = make_triangle(q.p[1], q.p[5], q.p[2], 0);
    const Triangle t_other = make_triangle(q.p[1], q.p[4], q.p[5], 0);
    int tested = 0;
    for (int i = 0; i < 80000; ++i) {
        const Vec3 target = on_segment(q.p[1], q.p[2], s(gen));
        const Vec3 origin = target + random_unit(gen) * 2.0f;
        if (!in_front_of_both(origin, q.p[1], q.first.normal, t.normal, 0.2f)) continue;
        const Ray ray{origin, normalize(target - origin)};
        ++tested;
        const bool either =
            hit(ray, q.first) < FLT_MAX || hit(ray, t) < FLT_MAX || hit(ray, t_other) < FLT_MAX;
        ASSERT_TRUE(either) << "ray " << i;
    }
    EXPECT_GT(tested, 8000);
}

// Coplanar neighbours (a floor of two quads): rays from above aimed at the shared edge.
TEST(ConvexQuad, CoplanarNeighboursAreWatertight) {
    std::mt19937 gen(13);
    std::uniform_real_distribution<float> s(0.0f, 1.0f), u(-1.0f, 1.0f);
    // Points of the plane z = 0.3 x - 0.2 y + 0.5, exact in float (multiples of 1/8).
    const auto at = [](float x, float y) { return Vec3(x, y, 0.25f * x - 0.125f * y + 0.5f); };
    const Vec3 a = at(0, 0), b = at(1.5f, 0.25f), c = at(1.25f, 2), d = at(-0.25f, 1.5f);
    const Vec3 e = at(3, 0.5f), f = at(2.75f, 2.5f);  // beyond b-c
    const ConvexQuad left = make_convex_quad(a, b, c, d, 0);
    const ConvexQuad right = make_convex_quad(b, e, f, c, 0);
    for (int i = 0; i < 40000; ++i) {
        const Vec3 target = on_segment(b, c, s(gen));
        const Vec3 origin = target + left.normal * (0.5f + s(gen)) * (i % 2 ? 1.0f : -1.0f) +
                            Vec3(u(gen), u(gen), u(gen));
        const Ray ray{origin, normalize(target - origin)};
        ASSERT_TRUE(hit(ray, left) < FLT_MAX || hit(ray, right) < FLT_MAX) << i;
    }
}

// Four parallelograms around a shared vertex, in a tilted plane: rays aimed exactly at the
// vertex, or at a point of one of the four edges that meet there, meet one of them.
TEST(ConvexQuad, WatertightAroundASharedVertex) {
    std::mt19937 gen(17);
    std::uniform_real_distribution<float> s(0.0f, 1.0f), u(-1.0f, 1.0f);
    for (float scale : {1e-3f, 1.0f, 1e4f}) {
        const Vec3 centre = Vec3(0.37f, -1.21f, 0.83f) * scale;
        const Vec3 du = Vec3(0.9f, 0.3f, 0.2f) * scale, dv = Vec3(-0.2f, 0.8f, 0.5f) * scale;
        const auto at = [&](int i, int j) { return centre + du * float(i) + dv * float(j); };
        ConvexQuad quads[4];
        int k = 0;
        for (int i = -1; i <= 0; ++i) {
            for (int j = -1; j <= 0; ++j)
                quads[k++] =
                    make_convex_quad(at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1), 0);
        }
        const Vec3 n = quads[0].normal;
        const Vec3 spokes[4] = {at(1, 0), at(0, 1), at(-1, 0), at(0, -1)};
        for (int i = 0; i < 20000; ++i) {
            const Vec3 target =
                i % 2 ? centre : on_segment(centre, spokes[i / 2 % 4], 0.9f * s(gen));
            const Vec3 origin = centre + (n * ((0.5f + s(gen)) * (i % 4 < 2 ? 1.0f : -1.0f)) +
                                          Vec3(u(gen), u(gen), u(gen))) *
                                             scale;
            const Ray ray{origin, normalize(target - origin)};
            bool any = false;
            for (const ConvexQuad& q : quads) any = any || hit(ray, q) < FLT_MAX;
            ASSERT_TRUE(any) << "scale " << scale << " ray " << i;
        }
    }
}

TEST(ConvexQuad, ParallelRaysNaNAndNoAreaMiss) {
    const ConvexQuad q = make_convex_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 0);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, q), 1.0f);
    EXPECT_EQ(hit({{0.5f, 0.5f, -1}, {0, 0, 1}}, q), 1.0f);  // from behind too
    EXPECT_EQ(hit({{0.5f, 0.5f, 0}, {1, 0, 0}}, q), FLT_MAX);  // in the plane, parallel
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {1, 0, 0}}, q), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, 1}}, q), FLT_MAX);  // pointing away
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, q, 0.5f), 0.5f);  // beyond t_max
    const float nan = std::nanf("");
    EXPECT_EQ(hit({{nan, 0.5f, 1}, {0, 0, -1}}, q), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, nan, -1}}, q), FLT_MAX);
    EXPECT_TRUE(std::isnan(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, q, nan)));  // t_max: no hit
    const ConvexQuad line = make_convex_quad({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}, 0);
    EXPECT_TRUE(is_black(line.normal));
    EXPECT_EQ(hit({{1.5f, 0, 1}, {0, 0, -1}}, line), FLT_MAX);
}

TEST(ConvexQuad, FrontIsTheTrianglesFrontAndPlaneFitsTheVertices) {
    const ConvexQuad q = make_convex_quad({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, 3);
    EXPECT_EQ(q.normal.z, 1.0f);
    EXPECT_EQ(q.plane_offset, 0.0f);
    EXPECT_EQ(q.material, 3);
    EXPECT_EQ(q.extent, 1.0f);
    const ConvexQuad back = make_convex_quad({0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}, 0);
    EXPECT_EQ(back.normal.z, -1.0f);
}

TEST(ConvexQuad, PlanarConvexQuadsAreOneOthersAreNot) {
    const auto planar_convex = [](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
        const Vec3 v[4] = {a, b, c, d};
        return is_planar_convex_quad(v);
    };
    // Parallelograms written in decimal and rounded to float, anywhere, at any tilt.
    std::mt19937 gen(5);
    std::uniform_real_distribution<double> uni(-1.0, 1.0);
    for (int i = 0; i < 2000; ++i) {
        const double scale = std::pow(10.0, 4 * uni(gen));
        double o[3], u[3], v[3];
        for (int k = 0; k < 3; ++k) {
            o[k] = uni(gen) * scale * 10;
            u[k] = uni(gen) * scale;
            v[k] = uni(gen) * scale;
        }
        const auto at = [&](double a, double b) {
            return Vec3(float(o[0] + a * u[0] + b * v[0]), float(o[1] + a * u[1] + b * v[1]),
                        float(o[2] + a * u[2] + b * v[2]));
        };
        const double cross_len = std::hypot(u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2],
                                            u[0] * v[1] - u[1] * v[0]);
        if (cross_len < 0.05 * scale * scale) continue;  // nearly a line: rounding may fold it
        EXPECT_TRUE(planar_convex(at(0, 0), at(1, 0), at(1, 1), at(0, 1))) << i;
    }
    EXPECT_TRUE(planar_convex({0, 0, 0}, {2, 0, 0}, {1.5f, 1, 0}, {0.5f, 1, 0}));  // trapezoid
    // Not planar: one corner lifted by 1e-3 of the size.
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 0, 0}, {1, 1, 1e-3f}, {0, 1, 0}));
    // Not convex: a dart, and a bow tie (the corners out of order).
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 0, 0}, {0.2f, 0.2f, 0}, {0, 1, 0}));
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}));
    // Degenerate: three corners on a line, and all four.
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {1, 1, 0}));
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}));
    EXPECT_FALSE(planar_convex({0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}));
    const float nan = std::nanf("");
    EXPECT_FALSE(planar_convex({0, 0, 0}, {1, 0, 0}, {1, 1, nan}, {0, 1, 0}));
}

TEST(ConvexQuad, StepOffEdgesStepsInsideEveryNearEdge) {
    const ConvexQuad q = make_convex_quad({0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, 0);
    const float m = 1e-3f;
    EXPECT_TRUE(is_black(step_off_edges(q, {1, 0.5f, 0}, m)));  // far from every edge
    const Vec3 corner = step_off_edges(q, {2, 1, 0}, m);         // on two edges
    EXPECT_FLOAT_EQ(corner.x, -m);
    EXPECT_FLOAT_EQ(corner.y, -m);
    EXPECT_EQ(corner.z, 0.0f);
    const Vec3 bottom = step_off_edges(q, {1, 0.5f * m, 0}, m);
    EXPECT_FLOAT_EQ(bottom.y, m);
    EXPECT_EQ(bottom.x, 0.0f);
}
