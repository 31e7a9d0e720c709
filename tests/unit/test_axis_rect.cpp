// Axis-aligned rectangles (axis_rect.h): classification, winding, hits agreeing with the same
// rectangle as a convex quad, watertight edges and corners between rectangles (a box's walls,
// a floor of two), guards that fail on NaN, parallel rays, and edge steps.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "axis_rect.h"
#include "convex_quad.h"

namespace {

float hit(const Ray& ray, const AxisRect& r, float t_max = FLT_MAX) {
    return intersect_rect(ray, r, t_max);
}

Vec3 random_unit(std::mt19937& gen) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (;;) {
        const Vec3 v(n(gen), n(gen), n(gen));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

AxisRect rect_of(Vec3 a, Vec3 b, Vec3 c, Vec3 d, int material = 0) {
    const Vec3 v[4] = {a, b, c, d};
    const int axis = axis_rect_axis(v);
    EXPECT_GE(axis, 0);
    return make_axis_rect(v, axis < 0 ? 0 : axis, material);
}

// The six faces of the box lo..hi as the scene files write them, each wound counter-clockwise
// seen from inside (as the Cornell box's walls): front sides inward.
std::vector<std::array<Vec3, 4>> box_faces(Vec3 lo, Vec3 hi) {
    const auto c = [&](int i, int j, int k) {
        return Vec3(i ? hi.x : lo.x, j ? hi.y : lo.y, k ? hi.z : lo.z);
    };
    return {{c(0, 0, 0), c(1, 0, 0), c(1, 1, 0), c(0, 1, 0)},   // z = lo, front +z
            {c(0, 0, 1), c(0, 1, 1), c(1, 1, 1), c(1, 0, 1)},   // z = hi, front -z
            {c(0, 0, 0), c(0, 1, 0), c(0, 1, 1), c(0, 0, 1)},   // x = lo, front +x
            {c(1, 0, 0), c(1, 0, 1), c(1, 1, 1), c(1, 1, 0)},   // x = hi, front -x
            {c(0, 0, 0), c(0, 0, 1), c(1, 0, 1), c(1, 0, 0)},   // y = lo, front +y
            {c(0, 1, 0), c(1, 1, 0), c(1, 1, 1), c(0, 1, 1)}};  // y = hi, front -y
}

}  // namespace

TEST(AxisRect, LayoutIsTwoRows) {
    EXPECT_EQ(alignof(AxisRect), 16u);
    EXPECT_EQ(sizeof(AxisRect), sizeof(real) == 4 ? 32u : 64u);
}

TEST(AxisRect, ClassifiesAxisAlignedRectanglesOnly) {
    const auto axis = [](Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
        const Vec3 v[4] = {a, b, c, d};
        return axis_rect_axis(v);
    };
    EXPECT_EQ(axis({0, 0, -1}, {1, 0, -1}, {1, 1, -1}, {0, 1, -1}), 2);  // the back wall
    EXPECT_EQ(axis({0, 0, 0}, {1, 0, 0}, {1, 0, -1}, {0, 0, -1}), 1);    // the floor
    EXPECT_EQ(axis({1, 0, 0}, {1, 1, 0}, {1, 1, -1}, {1, 0, -1}), 0);    // a side wall
    EXPECT_EQ(axis({0, 0, 0}, {0, 0, -1}, {0, 1, -1}, {0, 1, 0}), 0);    // the other winding
    EXPECT_EQ(axis({0, 0, 0}, {1, 1, 0}, {1, 0, 0}, {0, 1, 0}), -1);     // a bow tie
    EXPECT_EQ(axis({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 1e-7f}), -1);  // one corner off
    EXPECT_EQ(axis({0, 0, 0}, {1, 0.5f, 0}, {1, 1.5f, 0}, {0, 1, 0}), -1);  // a parallelogram
    EXPECT_EQ(axis({0, 0, 0}, {1, 0, 0}, {1, 0, 0}, {0, 0, 0}), -1);     // no area
    EXPECT_EQ(axis({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0.5f, 1, 0}), -1);  // a trapezoid
    const float nan = std::nanf("");
    EXPECT_EQ(axis({0, 0, 0}, {1, 0, 0}, {1, nan, 0}, {0, 1, 0}), -1);
}

TEST(AxisRect, FrontIsWhereTheTriangleOfItsWindingFaces) {
    for (const auto& f : box_faces({-1, -2, -3}, {4, 5, 6})) {
        const Vec3 v[4] = {f[0], f[1], f[2], f[3]};
        const AxisRect r = rect_of(f[0], f[1], f[2], f[3]);
        const Triangle t = make_triangle(f[0], f[1], f[2], 0);
        const Vec3 n = rect_normal(r);
        EXPECT_EQ(n.x, t.normal.x);
        EXPECT_EQ(n.y, t.normal.y);
        EXPECT_EQ(n.z, t.normal.z);
        // Reversed winding: the other side.
        const Vec3 reversed[4] = {v[0], v[3], v[2], v[1]};
        const AxisRect back = make_axis_rect(reversed, rect_axis(r), 0);
        EXPECT_EQ(rect_normal(back).x, -n.x);
        EXPECT_EQ(rect_normal(back).y, -n.y);
        EXPECT_EQ(rect_normal(back).z, -n.z);
        // Its own corners give it back, bit for bit.
        Vec3 corners[4];
        rect_corners(r, corners);
        const AxisRect again = make_axis_rect(corners, rect_axis(r), 0);
        EXPECT_EQ(std::memcmp(&again, &r, sizeof r), 0);
        float extent = 0.0f;
        for (const Vec3& p : v) extent = std::fmax(extent, max_component(abs(p)));
        EXPECT_EQ(r.extent, extent);
    }
}

TEST(AxisRect, HitsWhereTheSameConvexQuadDoes) {
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> uni(-2.0f, 3.0f);
    int hits = 0;
    for (const auto& f : box_faces({-0.5f, 0.25f, -1.5f}, {1.5f, 1.75f, 0.5f})) {
        const AxisRect r = rect_of(f[0], f[1], f[2], f[3]);
        const ConvexQuad q = make_convex_quad(f[0], f[1], f[2], f[3], 0);
        for (int i = 0; i < 5000; ++i) {
            const Vec3 origin(uni(gen), uni(gen), uni(gen));
            const Ray ray{origin, random_unit(gen)};
            const float tr = hit(ray, r);
            const float tq = intersect_quad(ray, RayShear(ray.direction), q, FLT_MAX);
            ASSERT_EQ(tr < FLT_MAX, tq < FLT_MAX) << i;
            if (tr < FLT_MAX) {
                ++hits;
                EXPECT_NEAR(tr, tq, 1e-5f * tq);
            }
        }
    }
    EXPECT_GT(hits, 500);
}

// Rays from inside a box aimed at its edges and corners, and at the edge between two halves
// of a split floor, meet some wall: at any scale and placement.
TEST(AxisRect, BoxEdgesAndCornersAreWatertight) {
    std::mt19937 gen(9);
    std::uniform_real_distribution<float> uni(0.05f, 0.95f), s(0.0f, 1.0f);
    const float scales[] = {1e-3f, 1.0f, 1e4f};
    for (float scale : scales) {
        for (Vec3 offset : {Vec3(0.0f), Vec3(123.456f, -78.9f, 4.2f)}) {
            const Vec3 lo = (offset + Vec3(-0.3f, -0.7f, -1.1f)) * scale;
            const Vec3 hi = (offset + Vec3(0.9f, 0.6f, 0.2f)) * scale;
            std::vector<AxisRect> walls;
            for (const auto& f : box_faces(lo, hi))
                walls.push_back(rect_of(f[0], f[1], f[2], f[3]));
            const auto corner = [&](int k) {
                return Vec3(k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z);
            };
            int leaks = 0;
            for (int i = 0; i < 30000; ++i) {
                const Vec3 inside(lo.x + (hi.x - lo.x) * uni(gen), lo.y + (hi.y - lo.y) * uni(gen),
                                  lo.z + (hi.z - lo.z) * uni(gen));
                Vec3 target = corner(i % 8);
                if (i % 3 != 0) {  // a point of an edge from this corner
                    const int axis = i / 8 % 3;
                    Vec3 other = target;
                    other = axis == 0   ? Vec3(target.x == lo.x ? hi.x : lo.x, target.y, target.z)
                            : axis == 1 ? Vec3(target.x, target.y == lo.y ? hi.y : lo.y, target.z)
                                        : Vec3(target.x, target.y, target.z == lo.z ? hi.z : lo.z);
                    // Moving along one axis keeps the other two coordinates exactly.
                    const float f = s(gen);
                    target =
                        axis == 0   ? Vec3(target.x + (other.x - target.x) * f, target.y, target.z)
                        : axis == 1 ? Vec3(target.x, target.y + (other.y - target.y) * f, target.z)
                                    : Vec3(target.x, target.y, target.z + (other.z - target.z) * f);
                }
                const Ray ray{inside, normalize(target - inside)};
                bool any = false;
                for (const AxisRect& w : walls) any = any || hit(ray, w) < FLT_MAX;
                leaks += !any;
            }
            EXPECT_EQ(leaks, 0) << "scale " << scale << " offset " << offset.x;
        }
    }
}

TEST(AxisRect, CoplanarNeighboursAreWatertight) {
    std::mt19937 gen(21);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), s(0.0f, 1.0f);
    // A floor y = 0.25 split at x = 0.3 into two, and a third piece meeting both at z = -0.7.
    const AxisRect left =
        rect_of({-1, 0.25f, 0}, {0.3f, 0.25f, 0}, {0.3f, 0.25f, -0.7f}, {-1, 0.25f, -0.7f});
    const AxisRect right =
        rect_of({0.3f, 0.25f, 0}, {1, 0.25f, 0}, {1, 0.25f, -0.7f}, {0.3f, 0.25f, -0.7f});
    const AxisRect back =
        rect_of({-1, 0.25f, -0.7f}, {1, 0.25f, -0.7f}, {1, 0.25f, -2}, {-1, 0.25f, -2});
    for (int i = 0; i < 40000; ++i) {
        Vec3 target =
            i % 2 ? Vec3(0.3f, 0.25f, -0.7f * s(gen)) : Vec3(2 * s(gen) - 1, 0.25f, -0.7f);
        if (i % 7 == 0) target = Vec3(0.3f, 0.25f, -0.7f);  // where all three meet
        const Vec3 origin = target + Vec3(u(gen), (0.2f + s(gen)) * (i % 4 < 2 ? 1 : -1), u(gen));
        const Ray ray{origin, normalize(target - origin)};
        ASSERT_TRUE(hit(ray, left) < FLT_MAX || hit(ray, right) < FLT_MAX ||
                    hit(ray, back) < FLT_MAX)
            << i;
    }
}

TEST(AxisRect, ParallelRaysAndNaNMiss) {
    const AxisRect r = rect_of({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, r), 1.0f);
    EXPECT_EQ(hit({{0.5f, 0.5f, -2}, {0, 0, 1}}, r), 2.0f);  // from behind too
    EXPECT_EQ(hit({{0.5f, 0.5f, 0}, {1, 0, 0}}, r), FLT_MAX);  // in the plane, parallel
    EXPECT_EQ(hit({{0.5f, 0.5f, 0}, {-0.0f, 0.6f, 0.8f * 0}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {1, 0, 0}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, 1}}, r), FLT_MAX);  // pointing away
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, r, 1.0f), 1.0f);  // not before t_max
    EXPECT_EQ(hit({{1.5f, 0.5f, 1}, {0, 0, -1}}, r), FLT_MAX);  // beside it
    EXPECT_EQ(hit({{1.0f, 1.0f, 1}, {0, 0, -1}}, r), 1.0f);  // its corner
    const float nan = std::nanf(""), inf = INFINITY;
    EXPECT_EQ(hit({{nan, 0.5f, 1}, {0, 0, -1}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, nan}, {0, 0, -1}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {nan, 0, -1}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {0, 0, nan}}, r), FLT_MAX);
    EXPECT_EQ(hit({{0.5f, 0.5f, 1}, {inf, 0, -1}}, r), FLT_MAX);
    EXPECT_TRUE(std::isnan(hit({{0.5f, 0.5f, 1}, {0, 0, -1}}, r, nan)));  // t_max: no hit
}

TEST(AxisRect, StepOffEdgesStepsInsideEveryNearEdge) {
    const AxisRect r = rect_of({0, 0, 0}, {0, 0, -1}, {0, 2, -1}, {0, 2, 0});  // x = 0
    const float m = 1e-3f;
    EXPECT_TRUE(is_black(step_off_edges(r, {0, 1, -0.5f}, m)));
    const Vec3 corner = step_off_edges(r, {0, 2, -1}, m);
    EXPECT_EQ(corner.x, 0.0f);
    EXPECT_EQ(corner.y, -m);
    EXPECT_EQ(corner.z, m);
    const Vec3 edge = step_off_edges(r, {0, 0.5f * m, -0.5f}, m);
    EXPECT_EQ(edge.y, m);
    EXPECT_EQ(edge.z, 0.0f);
}
