// Lab 02 Part B's rays, N at a time, one per SIMD lane: RayPacket, the per-lane shear of the
// watertight triangle test (RayShearN) and the helpers the packet intersection tests
// (packet_hits.h) and the packet tracer (packet_tracer.h) share.
//
// Written once for any lane type F: Float8 (8 AVX2 lanes, simd8.h) or Float16 (16 AVX-512
// lanes, simd16.h). Read F as Float8, MaskOf<F> as Mask8 and IntOf<F> as Int8.
#pragma once

#include <cstddef>

#include <geometry_set.h>
#include <simd8.h>  // and lane_math.h; a 16-lane build includes simd16.h first

// N rays, one per lane.
template <class F>
struct RayPacket {
    Vec3xN<F> origin;
    Vec3xN<F> direction;  // unit length

    Ray lane(int i) const { return {origin.lane(i), direction.lane(i)}; }
};

// The component of v that index k (0, 1, 2 per lane) names: v[k] lane by lane.
template <class F>
inline F component(const Vec3xN<F>& v, IntOf<F> k) {
    return select(k == 0, v.x, select(k == 1, v.y, v.z));
}

// RayShear (triangle.h) for N rays: every lane has its own axis permutation.
template <class F>
struct RayShearN {
    IntOf<F> kx, ky, kz;  // permuted axes, per lane
    F sx, sy;            // shear constants, per lane
    Vec3xN<F> origin_k;  // the ray origins permuted: (origin[kx], origin[ky], origin[kz])

    explicit RayShearN(const RayPacket<F>& ray) {
        using I = IntOf<F>;
        const Vec3xN<F>& d = ray.direction;
        const Vec3xN<F> a = abs(d);
        kz = select(a.x > a.y, select(a.x > a.z, I(0), I(2)), select(a.y > a.z, I(1), I(2)));
        kx = select(kz == 2, I(0), kz + 1);
        ky = select(kx == 2, I(0), kx + 1);
        const auto flip = component(d, kz) < 0.0f;  // keep the winding: swap kx and ky
        const I old_kx = kx;
        kx = select(flip, ky, kx);
        ky = select(flip, old_kx, ky);
        const F sz = F(1.0f) / component(d, kz);
        sx = component(d, kx) * sz;
        sy = component(d, ky) * sz;
        origin_k = {component(ray.origin, kx), component(ray.origin, ky),
                    component(ray.origin, kz)};
    }
};
using RayShear8 = RayShearN<Float8>;

// permuted(v, k) (simd8.h) reads 16 bytes at each vertex: the float after it must exist, as
// it does inside Triangle.
static_assert(offsetof(Triangle, v2) + 4 * sizeof(float) <= sizeof(Triangle),
              "permuted() reads one float past each vertex of a Triangle");
static_assert(offsetof(ConvexQuad, v3) + 4 * sizeof(float) <= sizeof(ConvexQuad),
              "permuted() reads one float past each vertex of a ConvexQuad");

// Component `axis` of every lane: the axis is the primitive's, the same in every lane.
template <class F>
inline const F& axis_component(const Vec3xN<F>& v, int axis) {
    return axis == 0 ? v.x : (axis == 1 ? v.y : v.z);
}

// The packet intersection tests (packet_hits.h) are forced inline, as the packet tracer's
// bounce_step is: g++ keeps the 16-lane triangle test out of line where two loops call it,
// and then reloads the packet's rays and shear from memory for every triangle (measured:
// 4-7% slower).
#define RT_PACKET_INLINE inline __attribute__((always_inline))
