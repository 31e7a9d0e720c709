// Pinhole camera: turns a point on the image plane into a primary ray.
#pragma once

#include <cmath>

#include <ray.h>

struct Camera {
    Vec3 position;     // centre of projection
    Vec3 upper_left;   // direction (unnormalised) to the image's upper-left corner
    Vec3 pixel_right;  // step across one pixel to the right
    Vec3 pixel_down;   // step across one pixel downwards

    // A camera at `position` looking at `target`, `vfov_degrees` vertical field of view,
    // for an image of width x height pixels.
    static Camera look_at(Vec3 position, Vec3 target, Vec3 up, real vfov_degrees, int width,
                          int height) {
        const double forward[3] = {double(target.x) - position.x, double(target.y) - position.y,
                                   double(target.z) - position.z};
        return looking_along(position, forward, up, vfov_degrees, width, height);
    }

    // A camera at `position` looking along `forward` (any length > 0). The frame is computed
    // in double and rounded once: a scene file's look_at may lie much nearer the camera than
    // the rounding of their coordinates (a look_at 1e-3 away from a camera 1e4 from the origin
    // aimed 12.6 degrees off when the difference was taken in float), so the loader keeps
    // the direction as the file writes it (host/scene.h) and the frame starts from it.
    static Camera looking_along(Vec3 position, const double (&forward)[3], Vec3 up,
                                real vfov_degrees, int width, int height) {
        const double f_length =
            std::sqrt(forward[0] * forward[0] + forward[1] * forward[1] + forward[2] * forward[2]);
        const double f[3] = {forward[0] / f_length, forward[1] / f_length, forward[2] / f_length};
        const double u[3] = {up.x, up.y, up.z};
        double r[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                       f[0] * u[1] - f[1] * u[0]};
        const double r_length = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        for (double& c : r) c /= r_length;
        const double v[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2],
                             r[0] * f[1] - r[1] * f[0]};  // the true up: right x forward
        const double half_height =
            std::tan(double(vfov_degrees) * 0.5 * 3.14159265358979323846 / 180.0);
        const double half_width = half_height * width / height;
        const double step_right = 2.0 * half_width / width;
        const double step_down = -2.0 * half_height / height;
        Camera c;
        c.position = position;
        c.pixel_right = {real(r[0] * step_right), real(r[1] * step_right), real(r[2] * step_right)};
        c.pixel_down = {real(v[0] * step_down), real(v[1] * step_down), real(v[2] * step_down)};
        c.upper_left = {real(f[0] - r[0] * half_width + v[0] * half_height),
                        real(f[1] - r[1] * half_width + v[1] * half_height),
                        real(f[2] - r[2] * half_width + v[2] * half_height)};
        return c;
    }

    // The ray through image point (x, y) in pixel units: (0, 0) is the upper-left corner of
    // the image, (width, height) the lower-right; pixel (i, j) covers [i, i+1) x [j, j+1).
    RT_HD Ray ray_through(real x, real y) const {
        return {position, normalize(upper_left + pixel_right * x + pixel_down * y)};
    }
};
