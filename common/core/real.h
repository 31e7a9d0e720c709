// The renderer's scalar type: float by default, double when built with -DRT_DOUBLE (the
// `-double` targets: make lab01-ref-double, make lab05-ref-double). Everything in common/core
// that is a coordinate, a distance, a direction or a radiance is a `real`; the random numbers
// stay float in both builds (rng.h), so a double image differs from the float one by
// rounding only. Images are written as float either way (image.cpp converts).
//
// The float-only spellings (sqrtf, fabsf, ...) would silently compute in float in the double
// build, so core code calls the overloads below instead. The float ones call exactly the
// functions the code called before, which keeps the float build's code, and images, as they
// were.
#pragma once

#include <cfloat>
#include <cmath>

#include <rt_hd.h>

#if defined(RT_DOUBLE)
using real = double;
constexpr real kRealMax = DBL_MAX;
constexpr real kRealMin = DBL_MIN;  // the smallest normal real
constexpr real kRealEpsilon = DBL_EPSILON;  // the spacing of reals at 1
constexpr const char* kPrecisionName = "double";
#else
using real = float;
constexpr real kRealMax = FLT_MAX;
constexpr real kRealMin = FLT_MIN;
constexpr real kRealEpsilon = FLT_EPSILON;
constexpr const char* kPrecisionName = "float";
#endif

RT_HD inline float sqrt_real(float x) { return sqrtf(x); }
RT_HD inline double sqrt_real(double x) { return sqrt(x); }
RT_HD inline float fabs_real(float x) { return fabsf(x); }
RT_HD inline double fabs_real(double x) { return fabs(x); }
RT_HD inline float copysign_real(float x, float y) { return copysignf(x, y); }
RT_HD inline double copysign_real(double x, double y) { return copysign(x, y); }
RT_HD inline float rint_real(float x) { return rintf(x); }
RT_HD inline double rint_real(double x) { return rint(x); }
