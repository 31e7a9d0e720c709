// Pinhole camera: turns a point on the image plane into a primary ray.
#pragma once

#include <cmath>

#include <ray.h>

struct Camera {
    Vec3 position;     // centre of projection
    Vec3 upper_left;   // direction (unnormalised) to the image's upper-left corner
    Vec3 pixel_right;  // step across one pixel to the right
    Vec3 pixel_down;   // step across one pixel downwards

    // A camera at `position` looking at `look_at`, `vfov_degrees` vertical field of view,
    // for an image of width x height pixels.
    static Camera look_at(Vec3 position, Vec3 target, Vec3 up, real vfov_degrees, int width,
                          int height) {
        const Vec3 forward = normalize(target - position);
        const Vec3 right = normalize(cross(forward, up));
        const Vec3 true_up = cross(right, forward);
        const real half_height = std::tan(vfov_degrees * 0.5f * real(3.14159265358979) / 180.0f);
        const real half_width = half_height * static_cast<real>(width) / static_cast<real>(height);
        Camera c;
        c.position = position;
        c.pixel_right = right * (2.0f * half_width / static_cast<real>(width));
        c.pixel_down = true_up * (-2.0f * half_height / static_cast<real>(height));
        c.upper_left = forward - right * half_width + true_up * half_height;
        return c;
    }

    // The ray through image point (x, y) in pixel units: (0, 0) is the upper-left corner of
    // the image, (width, height) the lower-right; pixel (i, j) covers [i, i+1) x [j, j+1).
    RT_HD Ray ray_through(real x, real y) const {
        return {position, normalize(upper_left + pixel_right * x + pixel_down * y)};
    }
};
