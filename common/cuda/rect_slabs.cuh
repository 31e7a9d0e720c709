// The axis-aligned rectangle as the megakernel tests it: a box of zero thickness (a "slab" on
// each axis), tested with the direction's three reciprocals, taken once per ray.
//
// A ray crosses the plane {p_k = c} at t = (c - o_k) / d_k, here c * (1/d_k) - o_k * (1/d_k)
// with one fused multiply-add: the reciprocals and the products o_k * (1/d_k) are the ray's
// (SlabRay), so each crossing costs one instruction, whose operand c the kernel reads from
// the constant bank. The rectangle's box [lo, hi] has lo = hi on its own axis, so the ray
// meets the rectangle where it enters every slab before it leaves any: entry = the latest of
// the three slabs' nearer crossings, exit = the earliest of their farther ones, and a hit at
// t = entry when entry <= exit (entry is then the crossing of the rectangle's plane).
//
// Watertight where rectangles share an edge: the edge's coordinates are the same numbers in
// both (the scene file's), and every crossing of {p_k = c} is computed by the same operations
// from the same operands, so the two rectangles compare the same two crossings in opposite
// directions. Where the floor y = 0 meets the back wall z = -1, the floor is hit when its
// plane's crossing t_y comes no later than the crossing of z = -1, t_z, and the wall when t_z
// comes no later than t_y: one of them always is. The core's rectangle test (axis_rect.h)
// divides instead, so a hit's distance may differ from lab 01's in its last bit.
#pragma once

#include <cmath>

#include <axis_rect.h>
#include <ray.h>

// A rectangle's box: lo and hi per axis (equal on its own axis), 16-byte rows so that a pool
// holds it in whole words.
struct alignas(16) RectSlab {
    real lo_x, lo_y, lo_z, unused_lo;
    real hi_x, hi_y, hi_z, unused_hi;
};
constexpr int kWordsPerSlab = static_cast<int>(sizeof(RectSlab) / 16);

// The box of an axis-aligned rectangle.
inline RectSlab rect_slab(const AxisRect& r) {
    const int axis = rect_axis(r), u = rect_axis_u(axis), v = rect_axis_v(axis);
    real lo[3], hi[3];
    lo[axis] = hi[axis] = r.plane;
    lo[u] = r.lo_u, hi[u] = r.hi_u;
    lo[v] = r.lo_v, hi[v] = r.hi_v;
    return {lo[0], lo[1], lo[2], real(0), hi[0], hi[1], hi[2], real(0)};
}

__device__ inline float fused_multiply_add(float a, float b, float c) { return fmaf(a, b, c); }
__device__ inline double fused_multiply_add(double a, double b, double c) { return fma(a, b, c); }
__device__ inline float min_number(float a, float b) { return fminf(a, b); }
__device__ inline double min_number(double a, double b) { return fmin(a, b); }
__device__ inline float max_number(float a, float b) { return fmaxf(a, b); }
__device__ inline double max_number(double a, double b) { return fmax(a, b); }

// What every slab test of one ray shares: the direction's reciprocals and the origin times
// them. A ray that meets nothing (NaN) gives NaN crossings, which fail every comparison.
struct SlabRay {
    Vec3 inverse;         // 1 / d per axis: +-infinity on an axis the ray runs parallel to
    Vec3 origin_scaled;   // o * (1 / d) per axis

    __device__ explicit SlabRay(const Ray& ray)
        : inverse(real(1) / ray.direction.x, real(1) / ray.direction.y, real(1) / ray.direction.z),
          origin_scaled(ray.origin * inverse) {}

    // Where the ray crosses {p_k = c}: the same operations for every rectangle that has c.
    __device__ real cross_x(real c) const {
        return fused_multiply_add(c, inverse.x, -origin_scaled.x);
    }
    __device__ real cross_y(real c) const {
        return fused_multiply_add(c, inverse.y, -origin_scaled.y);
    }
    __device__ real cross_z(real c) const {
        return fused_multiply_add(c, inverse.z, -origin_scaled.z);
    }
};

// The ray's entry into and exit from the slab's box. fminf and fmaxf drop a NaN operand (a
// crossing 0 * infinity, for an origin on a bound of an axis the ray runs parallel to).
struct SlabSpan {
    real entry, exit;
};
__device__ __forceinline__ SlabSpan slab_span(const SlabRay& ray, const RectSlab& s) {
    const real x0 = ray.cross_x(s.lo_x), x1 = ray.cross_x(s.hi_x);
    const real y0 = ray.cross_y(s.lo_y), y1 = ray.cross_y(s.hi_y);
    const real z0 = ray.cross_z(s.lo_z), z1 = ray.cross_z(s.hi_z);
    const real entry =
        max_number(max_number(min_number(x0, x1), min_number(y0, y1)), min_number(z0, z1));
    const real exit =
        min_number(min_number(max_number(x0, x1), max_number(y0, y1)), max_number(z0, z1));
    return {entry, exit};
}

// Whether the ray meets the rectangle at a distance in (0, t_max): then at span.entry.
__device__ __forceinline__ bool slab_hit(const SlabSpan& span, real t_max) {
    return (span.entry <= span.exit) & (span.entry > real(0)) & (span.entry < t_max);
}

// How many rectangles a kernel tests with a copy of the test per rectangle, each skipped by
// the whole warp past the scene's count; the rest go through a loop. In a copy the
// rectangle's number is a constant, so in the constant bank each of its numbers is an
// operand of the instruction that uses it (no load, no address arithmetic). Six: a box's
// walls; every copy past the scene's count still costs the warp a branch, and the kernel's
// code grows with each (handouts/05-cuda-mega.md measures 6 against 8).
constexpr int kUnrolledSlabs = 6;

// Calls f(i, slab i) for every one of `count` slabs, in order.
template <class F>
__device__ __forceinline__ void for_each_slab(const RectSlab* slabs, int count, F&& f) {
#pragma unroll
    for (int i = 0; i < kUnrolledSlabs; ++i) {
        if (i < count) f(i, slabs[i]);
    }
    for (int i = kUnrolledSlabs; i < count; ++i) f(i, slabs[i]);
}
