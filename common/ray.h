// A ray: origin plus unit direction; points along it are origin + t * direction.
#pragma once

#include "vec3.h"

struct Ray {
    Vec3 origin;     // where the ray starts
    Vec3 direction;  // unit length, so t is a distance

    RT_HD Vec3 at(float t) const { return origin + direction * t; }
};

// Start point for a ray leaving surface point p on the side of unit normal n.
// The offset scales with the magnitudes that bound p's rounding error (|p| and the
// distance travelled), never a fixed world-space epsilon, so a scene rendered at any scale
// from 1e-4 to 1e5 behaves the same.
RT_HD inline Vec3 offset_ray_origin(Vec3 p, Vec3 n, float distance_travelled) {
    constexpr float kRelativeOffset = 1.0f / (1 << 16);  // ~500 float ulps
    const float scale = max_component(abs(p)) + distance_travelled;
    return p + n * (scale * kRelativeOffset);
}
