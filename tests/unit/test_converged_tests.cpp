// The GPU's form of the primitive tests (kConvergedTests, rt_hd.h: no early return, one
// select at the end) returns the same bits as the CPU's for every ray: random rays and
// primitives, rays aimed at vertices and along edges, rays parallel to the plane, degenerate
// primitives, distances limited by t_max, and NaN. The GPU compiles the same source, so this
// checks on a CPU what its primitive loops compute.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "axis_rect.h"
#include "convex_quad.h"
#include "sphere.h"
#include "triangle.h"

namespace {

bool same_bits(real a, real b) { return std::memcmp(&a, &b, sizeof a) == 0; }

struct Cases {
    std::mt19937 gen{20261202};

    real uniform(real lo, real hi) { return std::uniform_real_distribution<real>(lo, hi)(gen); }
    Vec3 point(real r = 2) { return {uniform(-r, r), uniform(-r, r), uniform(-r, r)}; }
    Vec3 unit() {
        for (;;) {
            const Vec3 v = point(1);
            if (length(v) > real(1e-3)) return normalize(v);
        }
    }
    // A far limit, a near one that cuts hits off, or none.
    real t_max() {
        const int k = std::uniform_int_distribution<int>(0, 2)(gen);
        return k == 0 ? kRealMax : k == 1 ? uniform(real(0.1), real(6)) : real(1);
    }
    // Rays from random points: toward a random point, exactly at one of `aims` (vertices,
    // so rays through edges and corners), or along `along` (parallel to a plane).
    Ray ray(const std::vector<Vec3>& aims, Vec3 along) {
        const Vec3 origin = point(3);
        const int k = std::uniform_int_distribution<int>(0, 3)(gen);
        if (k == 0 && !aims.empty()) return {origin, normalize(aims[gen() % aims.size()] - origin)};
        if (k == 1) return {origin, along};
        return {origin, unit()};
    }
};

constexpr int kRays = 4000;

TEST(ConvergedTests, SpheresAgree) {
    Cases c;
    for (int shape = 0; shape < 50; ++shape) {
        const Sphere s{c.point(), c.uniform(real(0.05), real(1.5)), 0};
        for (int i = 0; i < kRays; ++i) {
            const Ray ray = c.ray({s.center, s.center + Vec3(s.radius, 0, 0)}, c.unit());
            const real t_max = c.t_max();
            const real cpu = intersect_sphere<false>(ray, s, t_max);
            const real gpu = intersect_sphere<true>(ray, s, t_max);
            ASSERT_TRUE(same_bits(cpu, gpu)) << cpu << " " << gpu;
        }
    }
}

TEST(ConvergedTests, TrianglesAgree) {
    Cases c;
    for (int shape = 0; shape < 50; ++shape) {
        const Vec3 a = c.point(), b = c.point();
        // Every tenth triangle is degenerate: its third vertex on the line through the others.
        const Vec3 d = shape % 10 == 0 ? a + (b - a) * real(0.25) : c.point();
        const Triangle tri = make_triangle(a, b, d, 0);
        for (int i = 0; i < kRays; ++i) {
            const Ray ray = c.ray({a, b, d, (a + b) * real(0.5)}, normalize(b - a));
            const RayShear shear(ray.direction);
            const real t_max = c.t_max();
            const real cpu = intersect_triangle<false>(ray, shear, tri, t_max);
            const real gpu = intersect_triangle<true>(ray, shear, tri, t_max);
            ASSERT_TRUE(same_bits(cpu, gpu)) << cpu << " " << gpu;
        }
    }
}

TEST(ConvergedTests, QuadsAgree) {
    Cases c;
    for (int shape = 0; shape < 50; ++shape) {
        const Vec3 v0 = c.point(), e1 = c.point(1), e2 = c.point(1);
        const ConvexQuad quad = make_convex_quad(v0, v0 + e1, v0 + e1 + e2, v0 + e2, 0);
        const std::vector<Vec3> corners = {quad.v0, quad.v1, quad.v2, quad.v3,
                                           (quad.v1 + quad.v2) * real(0.5)};
        for (int i = 0; i < kRays; ++i) {
            const Ray ray = c.ray(corners, normalize(e1));
            const RayShear shear(ray.direction);
            const real t_max = c.t_max();
            const real cpu = intersect_quad<false>(ray, shear, quad, t_max);
            const real gpu = intersect_quad<true>(ray, shear, quad, t_max);
            ASSERT_TRUE(same_bits(cpu, gpu)) << cpu << " " << gpu;
        }
    }
}

TEST(ConvergedTests, RectanglesAgree) {
    Cases c;
    for (int shape = 0; shape < 60; ++shape) {
        const int axis = shape % 3;
        const Vec3 lo = c.point(),
                   size(c.uniform(real(0.1), 2), c.uniform(real(0.1), 2), c.uniform(real(0.1), 2));
        Vec3 v[4];
        const int u = rect_axis_u(axis), w = rect_axis_v(axis);
        for (int k = 0; k < 4; ++k) {
            v[k] = lo;
            if (k == 1 || k == 2) v[k] = v[k] + along_axis(u, size[u]);
            if (k >= 2) v[k] = v[k] + along_axis(w, size[w]);
        }
        if (shape % 2) std::swap(v[1], v[3]);  // the other side faces front
        const AxisRect rect = make_axis_rect(v, axis_rect_axis(v), 0);
        for (int i = 0; i < kRays; ++i) {
            const Ray ray = c.ray({v[0], v[1], v[2], v[3]}, along_axis(u, real(1)));
            const real t_max = c.t_max();
            const real cpu = intersect_rect<false>(ray, rect, t_max);
            const real gpu = intersect_rect<true>(ray, rect, t_max);
            ASSERT_TRUE(same_bits(cpu, gpu)) << cpu << " " << gpu;
        }
    }
}

// The rectangle test as it was first written: the edge functions in canonical order, each
// multiplied by its sign. rect_contains_crossing folds the sign into the operands instead;
// the two must agree to the bit, or lab 02's packets (written in this form) leave lab 01.
real rect_as_first_written(const Ray& ray, const AxisRect& r, real t_max) {
    const int a = rect_axis(r);
    const int u = rect_axis_u(a), w = rect_axis_v(a);
    const real d_a = ray.direction[a];
    const real to_plane = r.plane - ray.origin[a];
    const real t = to_plane / d_a;
    const bool in_range = (t > 0.0f) & (t < t_max) & (fabs_real(d_a) > 0.0f);
    const real sign_a = copysign_real(real(1), d_a);
    const auto edge = [&](int other, real to_other, real d_other) {
        return a < other ? canonical_edge(to_plane, d_a, to_other, d_other)
                         : canonical_edge(to_other, d_other, to_plane, d_a);
    };
    const real sign_u = a < u ? sign_a : -sign_a, sign_w = a < w ? sign_a : -sign_a;
    const real lo_u = edge(u, r.lo_u - ray.origin[u], ray.direction[u]) * sign_u;
    const real hi_u = edge(u, r.hi_u - ray.origin[u], ray.direction[u]) * sign_u;
    const real lo_w = edge(w, r.lo_v - ray.origin[w], ray.direction[w]) * sign_w;
    const real hi_w = edge(w, r.hi_v - ray.origin[w], ray.direction[w]) * sign_w;
    const bool inside = (lo_u >= 0.0f) & (hi_u <= 0.0f) & (lo_w >= 0.0f) & (hi_w <= 0.0f);
    return (in_range & inside) ? t : t_max;
}

// The shadow ray's rectangle test culls before it divides; it must answer exactly as the
// closest-hit test does, for limits far, near, exactly at the hit, one ulp either side of it,
// and for rectangles from 1e-30 to 1e30 across.
TEST(ConvergedTests, RectangleBlocksIsTheTestItself) {
    Cases c;
    int hits = 0, at_limit = 0;
    for (int shape = 0; shape < 90; ++shape) {
        const int axis = shape % 3;
        const real scale = std::pow(real(10), real(shape % 15) * 4 - 28);  // 1e-28 .. 1e28
        const int u = rect_axis_u(axis), w = rect_axis_v(axis);
        Vec3 v[4];
        const Vec3 lo = c.point() * scale;
        const Vec3 size =
            Vec3(c.uniform(real(0.1), 2), c.uniform(real(0.1), 2), c.uniform(real(0.1), 2)) * scale;
        for (int k = 0; k < 4; ++k) {
            v[k] = lo;
            if (k == 1 || k == 2) v[k] = v[k] + along_axis(u, size[u]);
            if (k >= 2) v[k] = v[k] + along_axis(w, size[w]);
        }
        if (shape % 2) std::swap(v[1], v[3]);
        const int found = axis_rect_axis(v);
        if (found < 0) continue;  // corners that rounded together at this scale
        const AxisRect rect = make_axis_rect(v, found, 0);
        for (int i = 0; i < kRays; ++i) {
            Ray ray = c.ray({v[0], v[1], v[2], v[3]}, along_axis(u, real(1)));
            ray.origin = ray.origin * scale;
            if (i % 4 == 0) ray.direction = normalize(v[i / 4 % 4] - ray.origin);
            const real t_hit = intersect_rect<false>(ray, rect, kRealMax);
            real t_max = c.t_max() * scale;
            const int k = (i / 2) % 4;  // the limit at the hit, an ulp below or above, or drawn
            if (t_hit < kRealMax && k < 3) {
                t_max = k == 0 ? t_hit : std::nextafter(t_hit, k == 1 ? real(0) : kRealMax);
                ++at_limit;
            }
            const bool expected = intersect_rect<false>(ray, rect, t_max) < t_max;
            hits += expected;
            ASSERT_EQ(rect_blocks<false>(ray, rect, t_max), expected) << scale;
            ASSERT_EQ(rect_blocks<true>(ray, rect, t_max), expected) << scale;
            const real first = rect_as_first_written(ray, rect, t_max);
            ASSERT_TRUE(same_bits(intersect_rect<false>(ray, rect, t_max), first));
            ASSERT_TRUE(same_bits(intersect_rect<true>(ray, rect, t_max), first));
        }
    }
    EXPECT_GT(hits, 3000);  // the cases reach both answers
    EXPECT_GT(at_limit, 10000);
}

TEST(ConvergedTests, NaNRaysMissInBothForms) {
    const Ray nan_ray{Vec3(0.0f), Vec3(NAN, 0.0f, 1.0f)};
    const Sphere s{Vec3(0, 0, 3), 1, 0};
    const Triangle tri = make_triangle({-1, -1, 3}, {1, -1, 3}, {0, 1, 3}, 0);
    const ConvexQuad quad = make_convex_quad({-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}, 0);
    const Vec3 v[4] = {{-1, -1, 3}, {1, -1, 3}, {1, 1, 3}, {-1, 1, 3}};
    const AxisRect rect = make_axis_rect(v, axis_rect_axis(v), 0);
    const RayShear shear(nan_ray.direction);
    for (const real t_max : {real(10), kRealMax}) {
        EXPECT_EQ(intersect_sphere<true>(nan_ray, s, t_max), t_max);
        EXPECT_EQ(intersect_triangle<true>(nan_ray, shear, tri, t_max), t_max);
        EXPECT_EQ(intersect_quad<true>(nan_ray, shear, quad, t_max), t_max);
        EXPECT_EQ(intersect_rect<true>(nan_ray, rect, t_max), t_max);
        EXPECT_EQ(intersect_sphere<false>(nan_ray, s, t_max), t_max);
        EXPECT_EQ(intersect_rect<false>(nan_ray, rect, t_max), t_max);
    }
}

}  // namespace
