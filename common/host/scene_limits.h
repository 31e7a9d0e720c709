// What the renderer's arithmetic (common/core, in `real`: float, or double in the double
// build) can show, as the scene loader enforces it: every scene it accepts renders, and
// nothing in it vanishes silently. The bounds below are float's; the double build's follow
// the same reasoning with double's range: coordinates up to 1e30 (a product of three stays
// below 1e90, the triangle normal's squared length, edge^4, below 1e120, both far from
// DBL_MAX 1.8e308) and sizes from 1e-30 (their cubes and edge^4 far above DBL_MIN 2.2e-308).
// The relative bound stays: ray offsets are 2^-20 of the extent in both builds.
//  - Coordinates and radii up to 1e9 in magnitude: the triangle test multiplies three
//    coordinate differences (t_scaled in triangle.h), which stays far below FLT_MAX (3.4e38)
//    there; past ~1e12 it overflows and triangles vanish.
//  - Sizes (a radius, a triangle's longest edge) from 1e-9: their cubes stay far above
//    FLT_MIN (1.2e-38); a scene of size ~1e-13 underflows and vanishes.
//  - A size at least 2^-18 of the primitive's extent (its largest |coordinate|): ray offsets
//    are 2^-20 of the extent and more (ray.h), so such a primitive is at least a few offsets
//    across. Smaller, it sits below float precision at its distance from the origin.
//  - A triangle with an area as written must keep one when its vertices are rounded to
//    float (else its normal is zero and it is never hit). One that has no area as written is
//    kept: it has nothing to show.
//  - In the float build, no size below 2^-20 of the whole scene's extent (its largest
//    |coordinate| once centred, common/host/scene_centring.h): float's spacing there is
//    2^-23 of it and a ray that crossed the scene leaves a surface by 2^-20 of it (ray.h),
//    so such a detail is not placed, or not lit, where it is (a sphere of radius 1e-4 on a
//    floor of half-size 1e4 rendered the floor 10% too dark). Details down to 2^-14 of the
//    extent render with a warning (scene_report.h). The double build holds them; it says so.
// Each function returns what is wrong, or an empty string.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include <triangle.h>

#if defined(RT_DOUBLE)
constexpr double kMaxCoordinate = 1e30;
constexpr real kMinSize = 1e-30;
constexpr const char* kMaxCoordinateText = "1e30";  // as messages write the bounds
constexpr const char* kMinSizeText = "1e-30";
constexpr double kMaxNumber = DBL_MAX;  // any finite number a scene file gives
#else
constexpr double kMaxCoordinate = 1e9;
constexpr float kMinSize = 1e-9f;  // a float: a size written as 1e-9 rounds to it, not below
constexpr const char* kMaxCoordinateText = "1e9";
constexpr const char* kMinSizeText = "1e-9";
constexpr double kMaxNumber = 3.0e38;  // within float range
#endif
constexpr double kMinRelativeSize = 1.0 / (1 << 18);
constexpr double kMinSceneRelativeSize = 1.0 / (1 << 20);

inline std::string format_number(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", x);
    return text;
}

inline std::string coordinate_problem(double x) {
    if (std::fabs(x) <= kMaxCoordinate) return "";
    return std::string("expected a coordinate within +-") + kMaxCoordinateText +
           " (beyond it the renderer's " + kPrecisionName +
           " arithmetic overflows): scale the scene down or move it nearer the origin";
}

// `what` names the size ("a radius", ...) at the start of the message.
inline std::string size_problem(const char* what, double size, double extent) {
    if (size < kMinSize)
        return std::string(what) + " of " + format_number(size) + " is below " + kMinSizeText +
               ", too small for the renderer's " + kPrecisionName +
               " arithmetic: scale the scene up";
    if (size < kMinRelativeSize * extent)
        return std::string(what) + " of " + format_number(size) + " is too small for " +
               kPrecisionName + " precision that far from the origin (coordinates up to " +
               format_number(extent) + "): move the scene nearer the origin or make it larger";
    return "";
}

inline std::string sphere_problem(const Sphere& s) {
    if (s.radius > kMaxCoordinate)
        return "a radius of " + format_number(s.radius) + " is above " + kMaxCoordinateText +
               ", too large for the renderer's " + kPrecisionName +
               " arithmetic: scale the scene down";
    return size_problem("a radius", s.radius, sphere_extent(s));
}

// `written`: the vertices as the file gives them, before rounding to float; `tri`: as built.
inline std::string triangle_problem(const double (&written)[3][3], const Triangle& tri) {
    double e1[3], e2[3];
    for (int axis = 0; axis < 3; ++axis) {
        e1[axis] = written[1][axis] - written[0][axis];
        e2[axis] = written[2][axis] - written[0][axis];
    }
    const double cx = e1[1] * e2[2] - e1[2] * e2[1];
    const double cy = e1[2] * e2[0] - e1[0] * e2[2];
    const double cz = e1[0] * e2[1] - e1[1] * e2[0];
    if (cx == 0.0 && cy == 0.0 && cz == 0.0) return "";  // no area as written: nothing to show
    // The edges as written, in double: in float, a squared edge below 1e-19 underflows.
    const auto edge = [&](int a, int b) {
        return std::hypot(written[a][0] - written[b][0], written[a][1] - written[b][1],
                          written[a][2] - written[b][2]);
    };
    const double longest = std::fmax(edge(0, 1), std::fmax(edge(1, 2), edge(2, 0)));
    const std::string size = size_problem("a triangle with a longest edge", longest, tri.extent);
    if (!size.empty()) return size;
    if (is_black(tri.normal))
        return std::string("the triangle collapses to a line when its vertices are rounded to ") +
               kPrecisionName + ": make it larger or move it nearer the origin";
    return "";
}

// A size against the whole scene's centred extent (see above); the float build's limit only.
inline std::string scene_scale_problem(const char* what, double size, double scene_extent) {
#if defined(RT_DOUBLE)
    (void)what, (void)size, (void)scene_extent;
    return "";
#else
    if (!(size < kMinSceneRelativeSize * scene_extent)) return "";
    return std::string(what) + " of " + format_number(size) + " is below 2^-20 of the scene's " +
           "extent (" + format_number(scene_extent) + " from its centre), finer than float " +
           "arithmetic places it there: render the scene with the double build (make " +
           "lab01-ref-double), or make the detail larger or the scene smaller";
#endif
}
