// intersect_sphere: hits from outside and inside, misses, t_max, extreme scales against a
// double-precision reference, and no self-intersection after offset_ray_origin.
#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <random>

#include "ray.h"
#include "sphere.h"

namespace {

// Nearest root in (0, inf) of |o + t d - c| = r, in double from the same float inputs
// (d need not be exactly unit length); -1 for a miss.
double reference_t(const Ray& ray, const Sphere& s) {
    const double fx = double(ray.origin.x) - s.center.x, fy = double(ray.origin.y) - s.center.y,
                 fz = double(ray.origin.z) - s.center.z;
    const double dx = ray.direction.x, dy = ray.direction.y, dz = ray.direction.z;
    const double a = dx * dx + dy * dy + dz * dz;
    const double b = -(fx * dx + fy * dy + fz * dz) / a;  // closest approach
    const double px = fx + dx * b, py = fy + dy * b, pz = fz + dz * b;
    const double r = s.radius;
    const double disc = (r * r - (px * px + py * py + pz * pz)) / a;
    if (disc < 0) return -1;
    const double h = std::sqrt(disc);
    const double c = (fx * fx + fy * fy + fz * fz - r * r) / a;
    const double q = b + std::copysign(h, b);
    const double t1 = q != 0 ? c / q : 0, t2 = q;
    const double tn = std::fmin(t1, t2), tf = std::fmax(t1, t2);
    if (tn > 0) return tn;
    if (tf > 0) return tf;
    return -1;
}

Vec3 random_unit(std::mt19937& gen) {
    std::normal_distribution<float> n(0.0f, 1.0f);
    for (;;) {
        const Vec3 v(n(gen), n(gen), n(gen));
        if (length(v) > 1e-3f) return normalize(v);
    }
}

// A sphere of material 0 (irrelevant to intersection), field by field so that new members
// of Sphere do not break the tests.
Sphere sphere(Vec3 c, float r) {
    Sphere s{};
    s.center = c;
    s.radius = r;
    s.material = 0;
    return s;
}

}  // namespace

TEST(Sphere, HitFromOutsideHeadOn) {
    const Sphere s = sphere({0, 0, -5}, 1);
    const Ray ray{{0, 0, 0}, {0, 0, -1}};
    EXPECT_FLOAT_EQ(intersect_sphere(ray, s, FLT_MAX), 4.0f);
}

TEST(Sphere, HitFromOutsideOffAxis) {
    // Ray along -z at height y = 0.6 through a unit sphere at z = -5: enters at z = -5 + 0.8.
    const Sphere s = sphere({0, 0, -5}, 1);
    const Ray ray{{0, 0.6f, 0}, {0, 0, -1}};
    EXPECT_NEAR(intersect_sphere(ray, s, FLT_MAX), 4.2f, 1e-5f);
}

TEST(Sphere, HitFromInsideReturnsFarRoot) {
    const Sphere s = sphere({1, 2, 3}, 2);
    const Ray ray{{1, 2, 3}, {0, 1, 0}};
    EXPECT_FLOAT_EQ(intersect_sphere(ray, s, FLT_MAX), 2.0f);
    // Off-centre inside, both directions along the axis.
    const Ray up{{1, 2.5f, 3}, {0, 1, 0}};
    const Ray down{{1, 2.5f, 3}, {0, -1, 0}};
    EXPECT_FLOAT_EQ(intersect_sphere(up, s, FLT_MAX), 1.5f);
    EXPECT_FLOAT_EQ(intersect_sphere(down, s, FLT_MAX), 2.5f);
}

TEST(Sphere, MissSideways) {
    const Sphere s = sphere({0, 0, -5}, 1);
    const Ray ray{{0, 1.01f, 0}, {0, 0, -1}};
    EXPECT_EQ(intersect_sphere(ray, s, 123.0f), 123.0f);
}

TEST(Sphere, MissBehindOrigin) {
    const Sphere s = sphere({0, 0, 5}, 1);
    const Ray ray{{0, 0, 0}, {0, 0, -1}};
    EXPECT_EQ(intersect_sphere(ray, s, FLT_MAX), FLT_MAX);
}

TEST(Sphere, NearlyTangentRays) {
    // Rays at heights just inside and just outside the silhouette of a unit sphere.
    const Sphere s = sphere({0, 0, -10}, 1);
    const Ray inside{{0, 0.9999f, 0}, {0, 0, -1}};
    const Ray outside{{0, 1.0001f, 0}, {0, 0, -1}};
    const float t = intersect_sphere(inside, s, FLT_MAX);
    ASSERT_LT(t, FLT_MAX);
    EXPECT_NEAR(t, reference_t(inside, s), 1e-4);
    EXPECT_GT(t, 9.9f);
    EXPECT_LT(t, 10.0f);
    EXPECT_EQ(intersect_sphere(outside, s, FLT_MAX), FLT_MAX);
}

TEST(Sphere, TMaxIsRespected) {
    const Sphere s = sphere({0, 0, -5}, 1);
    const Ray ray{{0, 0, 0}, {0, 0, -1}};
    EXPECT_EQ(intersect_sphere(ray, s, 3.9f), 3.9f);     // near root beyond t_max
    EXPECT_FLOAT_EQ(intersect_sphere(ray, s, 4.1f), 4.0f);
    EXPECT_EQ(intersect_sphere(ray, s, 4.0f), 4.0f);     // the interval is open at t_max
    // From inside the far root must also respect t_max.
    const Ray in{{0, 0, -5}, {0, 0, -1}};
    EXPECT_EQ(intersect_sphere(in, s, 0.5f), 0.5f);
    EXPECT_FLOAT_EQ(intersect_sphere(in, s, 1.5f), 1.0f);
}

TEST(Sphere, RandomRaysMatchDoubleReference) {
    std::mt19937 gen(1);
    std::uniform_real_distribution<float> u(-3.0f, 3.0f);
    const Sphere s = sphere({0.3f, -0.2f, 0.1f}, 1.3f);
    int hits = 0, misses = 0;
    for (int i = 0; i < 20000; ++i) {
        const Ray ray{{u(gen), u(gen), u(gen)}, random_unit(gen)};
        const double ref = reference_t(ray, s);
        const float t = intersect_sphere(ray, s, FLT_MAX);
        ASSERT_FALSE(std::isnan(t));
        if (ref < 0) {
            ++misses;
            // Only a grazing ray may disagree; then t must still be near the surface.
            if (t != FLT_MAX) {
                const Vec3 p = ray.at(t) - s.center;
                EXPECT_NEAR(length(p), s.radius, 1e-4f);
            }
        } else if (ref > 1e-4) {
            ++hits;
            ASSERT_NEAR(t, ref, 1e-4 * (1.0 + ref)) << "ray " << i;
        }
    }
    EXPECT_GT(hits, 2000);
    EXPECT_GT(misses, 2000);
}

// A sphere of radius r seen from 1e4 r away, for r from 1e-4 to 1e5: rays aimed at points
// within 0.9 r of the centre (across the line of sight) hit with relative error < 1e-4.
TEST(Sphere, ExtremeScalesDistance1e4TimesRadius) {
    std::mt19937 gen(7);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (float r : {1e-4f, 1e-3f, 1e-2f, 1.0f, 1e2f, 1e4f, 1e5f}) {
        const Vec3 c = Vec3(0.37f, -0.81f, 0.52f) * (3.0f * r);  // not at the world origin
        const Sphere s = sphere(c, r);
        for (int i = 0; i < 2000; ++i) {
            const Vec3 dir_to_eye = random_unit(gen);
            const Vec3 eye = c + dir_to_eye * (1e4f * r);
            Vec3 t1, t2;
            orthonormal_basis(dir_to_eye, t1, t2);
            float a, b;
            do {
                a = u(gen);
                b = u(gen);
            } while (a * a + b * b > 0.81f);
            const Vec3 target = c + (t1 * a + t2 * b) * r;
            const Ray ray{eye, normalize(target - eye)};
            const double ref = reference_t(ray, s);
            ASSERT_GT(ref, 0) << "r=" << r;
            const float t = intersect_sphere(ray, s, FLT_MAX);
            ASSERT_LT(t, FLT_MAX) << "miss at r=" << r << " ray " << i;
            ASSERT_LT(std::fabs(t - ref) / ref, 1e-4) << "r=" << r << " t=" << t << " ref=" << ref;
        }
    }
}

// A tiny sphere (r = 1e-3) a thousand units away, off every axis: the textbook
// b^2 - c discriminant loses all digits (|f|^2 ~ 1e6 has an ulp of 0.06 >> r^2).
TEST(Sphere, TinySphereFarAway) {
    std::mt19937 gen(3);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    const float r = 1e-3f;
    const Vec3 c(577.35f, -577.35f, 577.35f);
    const Sphere s = sphere(c, r);
    int naive_wrong = 0;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 origin(u(gen), u(gen), u(gen));
        Vec3 t1, t2;
        const Vec3 view = normalize(c - origin);
        orthonormal_basis(view, t1, t2);
        const Vec3 target = c + (t1 * u(gen) + t2 * u(gen)) * (0.3f * r);
        const Ray ray{origin, normalize(target - origin)};
        const double ref = reference_t(ray, s);
        ASSERT_GT(ref, 0);
        const float t = intersect_sphere(ray, s, FLT_MAX);
        ASSERT_LT(t, FLT_MAX) << "ray " << i;
        ASSERT_LT(std::fabs(t - ref) / ref, 1e-4);
        // The textbook float discriminant, for contrast: it gets many of these wrong.
        const Vec3 f = ray.origin - c;
        const float bn = dot(f, ray.direction);
        const float naive_disc = bn * bn - (dot(f, f) - r * r);
        const double true_disc = double(r) * r * 0.91;  // at least 0.91 r^2 here
        if (!(std::fabs(naive_disc - true_disc) < true_disc)) ++naive_wrong;
    }
    EXPECT_GT(naive_wrong, 100) << "the case is not hard enough to mean anything";
}

// A ray leaving the surface outward from offset_ray_origin never re-hits its own sphere, at
// every scale, including spheres far from the world origin.
TEST(Sphere, NoSelfIntersectionLeavingOutward) {
    std::mt19937 gen(11);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    for (float scale : {1e-4f, 1e-2f, 1.0f, 1e3f, 1e5f}) {
        for (const Vec3 centre_unit : {Vec3(0.0f), Vec3(3.0f, -2.0f, 1.0f), Vec3(1000, 0, 0)}) {
            const Sphere s = sphere(centre_unit * scale, 1.0f * scale);
            int hits = 0;
            for (int i = 0; i < 5000; ++i) {
                const Vec3 n = random_unit(gen);
                const Vec3 p = s.center + n * s.radius;
                // Direction in the outward hemisphere, not too grazing.
                Vec3 d;
                do {
                    d = random_unit(gen);
                } while (dot(d, n) < 0.02f);
                const Ray ray{offset_ray_origin(p, n, u01(gen) * 10.0f * scale, sphere_extent(s)),
                              d};
                if (intersect_sphere(ray, s, FLT_MAX) < FLT_MAX) ++hits;
            }
            EXPECT_EQ(hits, 0) << "scale " << scale << " centre " << centre_unit.x;
        }
    }
}

// A ray refracted into the sphere from the offset point below the surface hits the far side,
// not its own entry point.
TEST(Sphere, RayLeavingInwardFindsFarSide) {
    std::mt19937 gen(12);
    for (float scale : {1e-4f, 1.0f, 1e5f}) {
        const Sphere s = sphere(Vec3(1.0f, 2.0f, 3.0f) * scale, scale);
        for (int i = 0; i < 2000; ++i) {
            const Vec3 n = random_unit(gen);
            const Vec3 p = s.center + n * s.radius;
            Vec3 d;
            do {
                d = random_unit(gen);
            } while (dot(d, n) > -0.1f);
            const Ray ray{offset_ray_origin(p, -n, 0.0f, sphere_extent(s)), d};
            const float t = intersect_sphere(ray, s, FLT_MAX);
            // Chord length from p along d is -2 (d.n) r.
            const float chord = -2.0f * dot(d, n) * s.radius;
            ASSERT_NEAR(t, chord, 1e-3f * s.radius) << "scale " << scale;
        }
    }
}
