// A ray: origin plus unit direction; points along it are origin + t * direction.
#pragma once

#include <real.h>  // also here: lab 02 Part A's vec3.h stands in for ours
#include <vec3.h>

struct Ray {
    Vec3 origin;     // where the ray starts
    Vec3 direction;  // unit length, so t is a distance

    RT_HD Vec3 at(real t) const { return origin + direction * t; }
};

// How far a new ray's origin leaves a surface, relative to the magnitudes that bound the hit
// point's rounding error (offset_ray_origin): 8 units in the last place of `real`, so 2^-20 in
// float and 2^-49 in double. An offset sized for float would stand a double ray 2^29 roundings
// off its surface, above details that double places exactly (a sphere of radius 1e-4 on a
// floor of half-size 1e4 cast no shadow); the scene limits follow the same number
// (host/scene_precision.h).
constexpr real kRelativeOffset = real(8) * kRealEpsilon;

// Start point for a ray leaving surface point p on the side of unit normal n. The offset must
// exceed the rounding error of p along n, so it is a fixed number of ulps of the magnitudes
// that bound that error, never a fixed world-space epsilon (so a scene rendered at any scale
// from 1e-4 to 1e5 behaves the same):
//  - |p| and the distance travelled: the rounding of p = origin + t * direction;
//  - the primitive's `extent` (its largest |coordinate|: vertices, or a sphere's |centre| +
//    radius): the intersection test subtracts the ray's origin from the primitive's
//    coordinates, so the hit distance's error grows with them, however near p lies to the
//    world origin. A floor of half-size 1e5 seen from a few units has |p| ~ 1 but
//    coordinates of 1e5 (pbrt bounds the error with the primitive too).
// kRelativeOffset of their sum is 8 to 16 ulps. Measured in float over random rays leaving
// triangles and spheres of sizes 1e-3..1e5 placed up to 1e4 from the origin, grazing ones
// included: no self-hit down to 2^-22, some at 2^-23; 2^-20 keeps a margin of 4
// (tests/unit/test_offset.cpp; in double, tests/precision/test_double.cpp).
RT_HD inline Vec3 offset_ray_origin(Vec3 p, Vec3 n, real distance_travelled, real extent) {
    const real scale = max_component(abs(p)) + distance_travelled + extent;
    return p + n * (scale * kRelativeOffset);
}
// How far offset_ray_origin moves p: the same arithmetic, for steps of the same size in
// other directions (step_off_edges, triangle.h).
RT_HD inline real ray_offset(Vec3 p, real distance_travelled, real extent) {
    return (max_component(abs(p)) + distance_travelled + extent) * kRelativeOffset;
}
