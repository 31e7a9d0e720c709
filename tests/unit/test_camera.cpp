// Pinhole camera: the image centre looks at the target, the corners span vfov and the aspect
// ratio, rays are unit length, up is up and x goes right.
#include <gtest/gtest.h>

#include <cmath>

#include "camera.h"
#include "scene.h"

namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double angle_between(Vec3 a, Vec3 b) {
    const double c = dot(a, b) / (double(length(a)) * length(b));
    return std::acos(std::fmax(-1.0, std::fmin(1.0, c)));
}

void expect_vec_near(Vec3 a, Vec3 b, float tol) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

}  // namespace

TEST(Camera, CentreLooksAtTarget) {
    const Vec3 eye(0.5f, 0.5f, 1.0f), target(0.5f, 0.5f, 0.0f);
    for (auto [w, h] : {std::pair{600, 600}, std::pair{640, 480}, std::pair{301, 799}}) {
        const Camera cam = Camera::look_at(eye, target, {0, 1, 0}, 55.0f, w, h);
        const Ray r = cam.ray_through(w * 0.5f, h * 0.5f);
        expect_vec_near(r.origin, eye, 0.0f);
        expect_vec_near(r.direction, {0, 0, -1}, 1e-6f);
    }
    // An oblique view.
    const Vec3 e2(3, -2, 5), t2(-1, 4, 0.5f);
    const Camera cam = Camera::look_at(e2, t2, {0, 0, 1}, 40.0f, 200, 100);
    expect_vec_near(cam.ray_through(100, 50).direction, normalize(t2 - e2), 1e-6f);
}

TEST(Camera, RaysAreUnitLength) {
    const Camera cam = Camera::look_at({1, 2, 3}, {-4, 0.5f, 2}, {0, 1, 0}, 70.0f, 320, 200);
    for (float x = 0; x <= 320; x += 13.7f)
        for (float y = 0; y <= 200; y += 9.1f)
            EXPECT_NEAR(length(cam.ray_through(x, y).direction), 1.0f, 1e-6f);
}

TEST(Camera, VerticalFieldOfViewAndAspect) {
    for (float vfov : {10.0f, 55.0f, 90.0f, 150.0f}) {
        for (auto [w, h] : {std::pair{600, 600}, std::pair{800, 400}, std::pair{300, 900}}) {
            const Camera cam = Camera::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, vfov, w, h);
            const Vec3 fwd(0, 0, -1);
            // Top and bottom edge centres are vfov/2 away from the axis.
            EXPECT_NEAR(angle_between(cam.ray_through(w / 2.0f, 0).direction, fwd), vfov / 2 * kDeg,
                        1e-5);
            EXPECT_NEAR(angle_between(cam.ray_through(w / 2.0f, h).direction, fwd), vfov / 2 * kDeg,
                        1e-5);
            // Left and right: the horizontal half-extent is aspect * tan(vfov/2).
            const double half_w = std::tan(vfov / 2 * kDeg) * w / h;
            EXPECT_NEAR(angle_between(cam.ray_through(0, h / 2.0f).direction, fwd),
                        std::atan(half_w), 1e-5);
            EXPECT_NEAR(angle_between(cam.ray_through(w, h / 2.0f).direction, fwd),
                        std::atan(half_w), 1e-5);
            // Corners, on the image plane at distance 1: (+-half_w, +-tan(vfov/2)).
            const Vec3 ul = cam.ray_through(0, 0).direction;
            EXPECT_NEAR(ul.x / -ul.z, -half_w, 1e-4 * (1 + half_w));
            EXPECT_NEAR(ul.y / -ul.z, std::tan(vfov / 2 * kDeg), 1e-4 * (1 + half_w));
            const Vec3 lr = cam.ray_through(w, h).direction;
            EXPECT_NEAR(lr.x / -lr.z, half_w, 1e-4 * (1 + half_w));
            EXPECT_NEAR(lr.y / -lr.z, -std::tan(vfov / 2 * kDeg), 1e-4 * (1 + half_w));
        }
    }
}

TEST(Camera, UpIsUpAndXGoesRight) {
    // Looking down -z with +y up: right is +x.
    const Camera cam = Camera::look_at({0, 0, 0}, {0, 0, -1}, {0, 1, 0}, 60.0f, 100, 100);
    EXPECT_GT(cam.ray_through(50, 0).direction.y, 0.1f);     // top row looks up
    EXPECT_LT(cam.ray_through(50, 100).direction.y, -0.1f);  // bottom row looks down
    EXPECT_GT(cam.ray_through(100, 50).direction.x, 0.1f);   // right column looks right
    EXPECT_LT(cam.ray_through(0, 50).direction.x, -0.1f);
    EXPECT_GT(cam.pixel_right.x, 0.0f);
    EXPECT_LT(cam.pixel_down.y, 0.0f);
    // The up hint need not be perpendicular to the view direction.
    const Camera tilted = Camera::look_at({0, 0, 0}, {0, -1, -1}, {0, 1, 0}, 60.0f, 100, 100);
    const Vec3 top = tilted.ray_through(50, 0).direction,
               bottom = tilted.ray_through(50, 100).direction;
    EXPECT_GT(top.y, bottom.y);
    EXPECT_NEAR(dot(tilted.pixel_right, tilted.pixel_down), 0.0f, 1e-9f);
    EXPECT_NEAR(dot(tilted.pixel_right, Vec3(0, 1, 0)), 0.0f, 1e-9f);  // horizon stays level
}

TEST(Camera, PixelStepsAreSquareAndOrthogonal) {
    const Camera cam = Camera::look_at({1, 1, 1}, {0, 0, 0}, {0, 1, 0}, 45.0f, 640, 360);
    EXPECT_NEAR(length(cam.pixel_right), length(cam.pixel_down), 1e-7f);
    EXPECT_NEAR(dot(cam.pixel_right, cam.pixel_down), 0.0f, 1e-9f);
    // Equal steps across the image: pixel (i, j)'s centre direction is linear in (i, j).
    const Vec3 a = cam.upper_left + cam.pixel_right * 10.5f + cam.pixel_down * 20.5f;
    expect_vec_near(normalize(a), cam.ray_through(10.5f, 20.5f).direction, 1e-6f);
}

TEST(Camera, CameraSpecForImageUsesItsFields) {
    CameraSpec spec;
    spec.position = {0, 0, 5};
    spec.look_at = {0, 0, 0};
    spec.vfov_degrees = 30.0f;
    const Camera cam = spec.for_image(400, 200);
    expect_vec_near(cam.position, {0, 0, 5}, 0.0f);
    EXPECT_NEAR(angle_between(cam.ray_through(200, 0).direction, {0, 0, -1}), 15 * kDeg, 1e-5);
}
