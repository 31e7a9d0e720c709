// Lab 02: your copy, yours to edit. Every place to fill in is marked TODO(lab02).
// Lab 02 Part B, the part students write: the intersection tests of N rays at once, one ray
// per SIMD lane, against one primitive. packet_tracer.h's closest-hit and shadow loops call
// them, one primitive after another. Start with intersect_rect (the Cornell box's walls);
// intersect_sphere, at the end, is a worked example of the pattern, given: read it first.
// Read F as Float8, MaskOf<F> as Mask8 and IntOf<F> as Int8: the lane types' operations
// (select, any, none, permuted, ...) are simd8.h's and lane_math.h's; RayPacket, RayShearN
// and axis_component are ray_packet.h's. Per lane the arithmetic must be the scalar test's,
// operation for operation (common/core/sphere.h, triangle.h, convex_quad.h, axis_rect.h):
// lab 02's image is lab 01's, bit for bit (tests/labs/test_lab02.py).
#pragma once

#include <ray_packet.h>

// intersect_rect (axis_rect.h) for N rays against one axis-aligned rectangle. Its axis is the
// same in every lane, so it picks registers, not lanes: one division and four sign tests.
template <class F>
RT_PACKET_INLINE F intersect_rect(const RayPacket<F>& ray, const AxisRect& r, F t_max) {
    // TODO(lab02): intersect_rect (common/core/axis_rect.h) in all lanes: the rectangle's
    // axis is the same in every lane, so it picks a register (axis_component), not lanes;
    // t = (plane - o_a) / d_a, then the four canonical edge functions (two rounded
    // products, never fused), their signs read as the scalar test reads them.
    // Until then: lane 0 only, with the scalar test, so 7 of every 8 samples miss the
    // Cornell box's walls.
    const float t0 = intersect_rect(ray.lane(0), r, t_max.lane(0));
    return select(MaskOf<F>::first(1), F(t0), t_max);
}

// intersect_triangle (triangle.h) for N rays against one triangle: per lane the distance in
// (0, t_max), or t_max for a miss. Watertight in every lane, as the scalar test.
template <class F>
RT_PACKET_INLINE F intersect_triangle(const RayPacket<F>& ray, const RayShearN<F>& shear,
                                      const Triangle& tri, F t_max) {
    using Mask = MaskOf<F>;
    // The plane cull, as in the scalar test; it only rejects. The negated predicates are
    // true for NaN, as !(x <= 0) is in the scalar code.
    const Vec3xN<F> normal(tri.normal);
    const F denom = dot(normal, ray.direction);
    const F num = F(tri.plane_offset) - dot(normal, ray.origin);
    const Mask not_behind = not_less_equal(num * denom, F(0.0f));
    const Mask not_beyond = not_greater_equal(abs(num), t_max * 1.00001f * abs(denom));
    const Mask candidates = not_behind & not_beyond;
    // No lane left: a third of the Cornell box's closest-hit tests end here, half of its
    // shadow-ray tests.
    if (none(candidates)) return t_max;

    // TODO(lab02): the watertight test of intersect_triangle (common/core/triangle.h) in all
    // lanes at once: the vertices relative to the origin in each lane's own axis order
    // (permuted(tri.v0, shear.kx) - shear.origin_k.x, ...), the shear (shear.sx ...),
    // the three edge functions as a product minus a product (never fused), the
    // double-precision redo for lanes where one of them is zero, the sign tests, det,
    // and the plane's t = num / denom in the lanes that hit (det != 0, t in (0, t_max)).
    // Every other lane returns its t_max.
    // Until then: lane 0 only, with the scalar test, so 7 of every 8 samples miss
    // every triangle.
    (void)candidates;
    (void)shear;
    const Ray ray0 = ray.lane(0);
    const float t0 = intersect_triangle(ray0, RayShear(ray0.direction), tri, t_max.lane(0));
    return select(Mask::first(1), F(t0), t_max);
}

// intersect_quad (convex_quad.h) for N rays against one quad: the plane cull, the four edge
// functions of the sheared vertices as the triangle test computes them, and the plane's t.
template <class F>
RT_PACKET_INLINE F intersect_quad(const RayPacket<F>& ray, const RayShearN<F>& shear,
                                  const ConvexQuad& quad, F t_max) {
    using Mask = MaskOf<F>;
    const Vec3xN<F> normal(quad.normal);
    const F denom = dot(normal, ray.direction);
    const F num = F(quad.plane_offset) - dot(normal, ray.origin);
    const Mask not_behind = not_less_equal(num * denom, F(0.0f));
    const Mask not_beyond = not_greater_equal(abs(num), t_max * 1.00001f * abs(denom));
    const Mask candidates = not_behind & not_beyond;
    if (none(candidates)) return t_max;

    // TODO(lab02): intersect_quad (common/core/convex_quad.h) in all lanes: as your
    // intersect_triangle, with four edge functions (v0v1, v1v2, v2v3, v3v0, each computed
    // as the triangle computes the same edge) and the plane's t = num / denom.
    // Until then: lane 0 only, with the scalar test.
    (void)candidates;
    const Ray ray0 = ray.lane(0);
    const float t0 = intersect_quad(ray0, RayShear(ray0.direction), quad, t_max.lane(0));
    (void)shear;
    return select(Mask::first(1), F(t0), t_max);
}

// The worked example, given: intersect_sphere (sphere.h) for N rays against one sphere: per
// lane the distance in (0, t_max), or t_max for a miss. The pattern: the scalar code line for
// line; a branch becomes a mask; the early exit happens only when all lanes miss.
template <class F>
RT_PACKET_INLINE F intersect_sphere(const RayPacket<F>& ray, const Sphere& s, F t_max) {
    const Vec3xN<F> f = ray.origin - Vec3xN<F>(s.center);
    const F b = -dot(f, ray.direction);
    const Vec3xN<F> perpendicular = f + ray.direction * b;
    const F r2 = s.radius * s.radius;
    const F disc = r2 - length_squared(perpendicular);
    const auto crosses = disc >= 0.0f;  // false for NaN, as !(disc >= 0) in the scalar code
    if (none(crosses)) return t_max;
    // Lanes with disc < 0 compute NaN from here on; `crosses` masks them out at the end.
    const F q = b + copysign(sqrt(disc), b);
    const F c = length_squared(f) - r2;
    const F t_a = c / q;
    const F t_b = q;
    const F t_near = min(t_a, t_b);
    const F t_far = max(t_a, t_b);
    const auto near_ok = (t_near > 0.0f) & (t_near < t_max);
    const auto far_ok = (t_far > 0.0f) & (t_far < t_max);
    return select(crosses, select(near_ok, t_near, select(far_ok, t_far, t_max)), t_max);
}
