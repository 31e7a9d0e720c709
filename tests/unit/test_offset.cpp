// Ray offsets and primitives at extreme sizes: no ray leaving a floor or sphere of size up to
// 1e5 hits it again, even seen from a few units away and far from the world origin; and
// triangles with edges far outside 1e-11..1e9 still get their normal (and are hit).
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>

#include "path_tracer.h"

namespace {

enum Kind { kTriangle, kSphere, kQuad, kRect };

struct Surface {
    Triangle triangle{};
    Sphere sphere{};
    ConvexQuad quad{};
    AxisRect rect{};
    Kind kind = kTriangle;
};

float hit(const Surface& s, const Ray& ray) {
    switch (s.kind) {
        case kSphere: return intersect_sphere(ray, s.sphere, FLT_MAX);
        case kQuad: return intersect_quad(ray, RayShear(ray.direction), s.quad, FLT_MAX);
        case kRect: return intersect_rect(ray, s.rect, FLT_MAX);
        default: return intersect_triangle(ray, RayShear(ray.direction), s.triangle, FLT_MAX);
    }
}

// Rays through a camera a few units from a huge surface (a triangle, convex quad or
// axis-aligned rectangle of half-size `half` or a sphere of radius `half`, tilted at random
// but the rectangle, placed near `where`) hit it, then leave it from
// the offset point in random directions of the hemisphere, a third of them grazing. Returns
// how many of those hit the surface they left.
int self_hits(float half, Vec3 where, Kind kind, std::mt19937& gen, int surfaces = 40) {
    const bool sphere = kind == kSphere;
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    int hits = 0;
    for (int k = 0; k < surfaces; ++k) {
        Vec3 n = normalize(Vec3(u(gen) - 0.5f, u(gen) - 0.5f, u(gen) - 0.5f));
        if (k % 4 == 0 || kind == kRect) n = Vec3(0, 1, 0);  // axis-aligned floors too
        Vec3 t, b;
        orthonormal_basis(n, t, b);
        if (kind == kRect) t = Vec3(1, 0, 0), b = Vec3(0, 0, -1);
        const Vec3 c0 = where + Vec3(u(gen) - 0.5f, u(gen) - 0.5f, u(gen) - 0.5f) * 4.0f;
        Surface s;
        s.kind = kind;
        s.sphere = {c0 - n * half, half, 0};
        s.triangle =
            make_triangle(c0 - t * half - b * half, c0 + t * half - b * half, c0 + b * half, 0);
        const Vec3 corners[4] = {c0 - t * half - b * half, c0 + t * half - b * half,
                                 c0 + t * half + b * half, c0 - t * half + b * half};
        s.quad = make_convex_quad(corners[0], corners[1], corners[2], corners[3], 0);
        if (kind == kRect) s.rect = make_axis_rect(corners, 1, 0);
        const float extent = sphere          ? sphere_extent(s.sphere)
                             : kind == kQuad ? s.quad.extent
                             : kind == kRect ? s.rect.extent
                                             : s.triangle.extent;
        for (int i = 0; i < 100; ++i) {
            const Vec3 camera = c0 + n * (1.0f + 3.0f * u(gen)) + t * ((u(gen) - 0.5f) * 4.0f);
            const Vec3 target = c0 + t * ((u(gen) - 0.5f) * 20.0f) + b * ((u(gen) - 0.5f) * 20.0f);
            const Ray primary{camera, normalize(target - camera)};
            const float th = hit(s, primary);
            if (th == FLT_MAX) continue;
            const Vec3 p = primary.at(th);
            const Vec3 normal = sphere          ? normalize(p - s.sphere.center)
                                : kind == kQuad ? s.quad.normal
                                : kind == kRect ? rect_normal(s.rect)
                                                : s.triangle.normal;
            const Vec3 facing = dot(primary.direction, normal) < 0.0f ? normal : -normal;
            const Vec3 origin = offset_ray_origin(p, facing, th, extent);
            for (int j = 0; j < 15; ++j) {
                Vec3 d = sample_cosine_hemisphere(facing, u(gen), u(gen));
                if (j % 3 == 0) d = normalize(d + (d - facing * dot(d, facing)) * 20.0f);
                if (dot(d, facing) <= 0.0f) continue;
                if (hit(s, {origin, d}) < FLT_MAX) ++hits;
            }
        }
    }
    return hits;
}

}  // namespace

// The former offset, (|p| + t) * 2^-16 without the extent, let 3961 and 13916 of these rays
// hit a triangle of half-size 1e4 and 1e5 near the origin again (spheres: 6240 and 13560):
// shadow acne that made such a floor render 38% too dark (checks.check_large_primitives).
TEST(Offset, NoSelfHitLeavingHugeTriangles) {
    std::mt19937 gen(5);
    for (float half : {1e3f, 1e4f, 1e5f}) {
        for (const Vec3 where : {Vec3(0.0f), Vec3(1e4f, -7e3f, 3e3f)}) {
            EXPECT_EQ(self_hits(half, where, kTriangle, gen), 0)
                << "half-size " << half << " at " << where.x;
        }
    }
}

TEST(Offset, NoSelfHitLeavingHugeSpheres) {
    std::mt19937 gen(6);
    for (float radius : {1e3f, 1e4f, 1e5f}) {
        for (const Vec3 where : {Vec3(0.0f), Vec3(1e4f, -7e3f, 3e3f)}) {
            EXPECT_EQ(self_hits(radius, where, kSphere, gen), 0)
                << "radius " << radius << " at " << where.x;
        }
    }
}

TEST(Offset, NoSelfHitLeavingHugeQuadsAndRectangles) {
    std::mt19937 gen(7);
    for (const Kind kind : {kQuad, kRect}) {
        for (float half : {1e3f, 1e4f, 1e5f}) {
            for (const Vec3 where : {Vec3(0.0f), Vec3(1e4f, -7e3f, 3e3f)}) {
                EXPECT_EQ(self_hits(half, where, kind, gen), 0)
                    << (kind == kQuad ? "quad" : "rectangle") << " half-size " << half << " at "
                    << where.x;
            }
        }
    }
}

// The float cross product's squared length overflows past edges of ~1e9 and underflows below
// ~1e-11; the normal is computed in double, so these triangles keep a unit normal, the right
// plane and a hit.
TEST(Offset, TrianglesOfExtremeSizeKeepTheirNormal) {
    for (float size : {1e-30f, 1e-15f, 1e-11f, 1.0f, 1e9f, 1e12f, 1e20f}) {
        const Vec3 normal = normalize(Vec3(0.3f, 1.0f, -0.2f));
        Vec3 t, b;
        orthonormal_basis(normal, t, b);
        const Triangle tri = make_triangle(Vec3(0.0f), t * size, b * size, 0);
        EXPECT_NEAR(length(tri.normal), 1.0f, 1e-6f) << "size " << size;
        EXPECT_GT(dot(tri.normal, normal), 0.9999f) << "size " << size;
        EXPECT_NEAR(tri.plane_offset, 0.0f, 1e-6f * size) << "size " << size;
        EXPECT_EQ(tri.extent,
                  max_float(max_component(abs(t * size)), max_component(abs(b * size))));
    }
    // The largest sizes whose intersection test stays in float range (scene_limits.h) are hit.
    for (float size : {1e-9f, 1.0f, 1e9f}) {
        const Triangle tri = make_triangle({-size, 0, -size}, {-size, 0, size}, {size, 0, 0}, 0);
        const Ray down{{0, size, 0}, {0, -1, 0}};
        EXPECT_FLOAT_EQ(intersect_triangle(down, RayShear(down.direction), tri, FLT_MAX), size)
            << "size " << size;
    }
}
