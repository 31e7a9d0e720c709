// Lab 02 Part B, the part students write: the intersection tests of N rays at once, one ray
// per SIMD lane, against one primitive. packet_tracer.h's closest-hit and shadow loops call
// them, one primitive after another. Start with intersect_rect (the Cornell box's walls);
// intersect_sphere, at the end, is a worked example of the pattern, given: read it first.
// Read F as Float8, MaskOf<F> as Mask8 and IntOf<F> as Int8: the lane types' operations
// (select, any, none, permuted, ...) are simd8.h's and lane_math.h's; RayPacket, RayShearN
// and axis_component are ray_packet.h's. Per lane the arithmetic must be the scalar test's,
// operation for operation (common/core/sphere.h, triangle.h, convex_quad.h, axis_rect.h):
// lab 02's image is lab 01's, bit for bit (tests/labs/test_lab02.py).
//!
//! Lab 02 students write the regions between BEGIN/END SOLUTION; labkit/skeletons.py turns
//! this file into labs/02-simd/skeleton/packet_hits.h, which stands in for it in ./lab02's
//! build (first on the include path).
#pragma once

#include <ray_packet.h>

// intersect_rect (axis_rect.h) for N rays against one axis-aligned rectangle. Its axis is the
// same in every lane, so it picks registers, not lanes: one division and four sign tests.
template <class F>
RT_PACKET_INLINE F intersect_rect(const RayPacket<F>& ray, const AxisRect& r, F t_max) {
    // BEGIN SOLUTION
    const int a = rect_axis(r);
    const int u = rect_axis_u(a), w = rect_axis_v(a);
    const F& d_a = axis_component(ray.direction, a);
    const F to_plane = F(r.plane) - axis_component(ray.origin, a);
    const F t = to_plane / d_a;
    const auto crosses = (t > 0.0f) & (t < t_max) & (abs(d_a) > 0.0f);
    if (none(crosses)) return t_max;
    const F& d_u = axis_component(ray.direction, u);
    const F& d_w = axis_component(ray.direction, w);
    const F& o_u = axis_component(ray.origin, u);
    const F& o_w = axis_component(ray.origin, w);
    const F sign_a = copysign(F(1.0f), d_a);
    const F sign_u = a < u ? sign_a : -sign_a;
    const F sign_w = a < w ? sign_a : -sign_a;
    // canonical_edge (axis_rect.h): the lower axis first, two rounded products, never fused.
    const auto edge = [&](int other, F to_other, const F& d_other) {
        return a < other ? to_plane * d_other - to_other * d_a
                         : to_other * d_a - to_plane * d_other;
    };
    const F lo_u = edge(u, F(r.lo_u) - o_u, d_u) * sign_u;
    const F hi_u = edge(u, F(r.hi_u) - o_u, d_u) * sign_u;
    const F lo_w = edge(w, F(r.lo_v) - o_w, d_w) * sign_w;
    const F hi_w = edge(w, F(r.hi_v) - o_w, d_w) * sign_w;
    const auto inside = (lo_u >= 0.0f) & (hi_u <= 0.0f) & (lo_w >= 0.0f) & (hi_w <= 0.0f);
    return select(crosses & inside, t, t_max);
    // SKELETON
    //> // TODO(lab02): intersect_rect (common/core/axis_rect.h) in all lanes: the rectangle's
    //> // axis is the same in every lane, so it picks a register (axis_component), not lanes;
    //> // t = (plane - o_a) / d_a, then the four canonical edge functions (two rounded
    //> // products, never fused), their signs read as the scalar test reads them.
    //> // Until then: lane 0 only, with the scalar test, so 7 of every 8 samples miss the
    //> // Cornell box's walls.
    //> const float t0 = intersect_rect(ray.lane(0), r, t_max.lane(0));
    //> return select(MaskOf<F>::first(1), F(t0), t_max);
    // END SOLUTION
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

    // BEGIN SOLUTION
    // Vertices relative to the origin, in each lane's permuted axis order: a[kx] is
    // v0[kx] - origin[kx], and one permute picks v0[kx] for all lanes.
    const F az = permuted(tri.v0, shear.kz) - shear.origin_k.z;
    const F bz = permuted(tri.v1, shear.kz) - shear.origin_k.z;
    const F cz = permuted(tri.v2, shear.kz) - shear.origin_k.z;
    // Shear: a product, then a difference, never fused (see edge_function in triangle.h).
    const F ax = (permuted(tri.v0, shear.kx) - shear.origin_k.x) - shear.sx * az;
    const F ay = (permuted(tri.v0, shear.ky) - shear.origin_k.y) - shear.sy * az;
    const F bx = (permuted(tri.v1, shear.kx) - shear.origin_k.x) - shear.sx * bz;
    const F by = (permuted(tri.v1, shear.ky) - shear.origin_k.y) - shear.sy * bz;
    const F cx = (permuted(tri.v2, shear.kx) - shear.origin_k.x) - shear.sx * cz;
    const F cy = (permuted(tri.v2, shear.ky) - shear.origin_k.y) - shear.sy * cz;

    // The edge functions as edge_function(): two rounded products, one rounded difference.
    // An FMA here (_mm256_fmsub_ps) would break watertightness.
    F u = cx * by - cy * bx;
    F v = ax * cy - ay * cx;
    F w = bx * ay - by * ax;

    // Rare: a lane on an edge, or rounded to zero. Redo those lanes in double, one by one.
    const Mask on_edge = candidates & ((u == 0.0f) | (v == 0.0f) | (w == 0.0f));
    if (any(on_edge)) redo_edges_exactly(on_edge, ax, ay, bx, by, cx, cy, u, v, w);
    const Mask any_negative = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    const Mask any_positive = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    const Mask inside = and_not(candidates, any_negative & any_positive);

    // The distance is the plane's, num / denom of the cull: exact enough for a needle too.
    const F det = u + v + w;
    const F t = num / denom;
    const Mask hit = inside & (det != 0.0f) & (t > 0.0f) & (t < t_max);
    // No early exit when no lane hits: a branch that goes either way costs more than the
    // few instructions it would skip (measured: 5%).
    return select(hit, t, t_max);
    // SKELETON
    //> // TODO(lab02): the watertight test of intersect_triangle (common/core/triangle.h) in all
    //> // lanes at once: the vertices relative to the origin in each lane's own axis order
    //> // (permuted(tri.v0, shear.kx) - shear.origin_k.x, ...), the shear (shear.sx ...),
    //> // the three edge functions as a product minus a product (never fused), the
    //> // double-precision redo for lanes where one of them is zero, the sign tests, det,
    //> // and the plane's t = num / denom in the lanes that hit (det != 0, t in (0, t_max)).
    //> // Every other lane returns its t_max.
    //> // Until then: lane 0 only, with the scalar test, so 7 of every 8 samples miss
    //> // every triangle.
    //> (void)candidates;
    //> (void)shear;
    //> const Ray ray0 = ray.lane(0);
    //> const float t0 = intersect_triangle(ray0, RayShear(ray0.direction), tri, t_max.lane(0));
    //> return select(Mask::first(1), F(t0), t_max);
    // END SOLUTION
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

    // BEGIN SOLUTION
    const Vec3* vertex[4] = {&quad.v0, &quad.v1, &quad.v2, &quad.v3};
    F x[4], y[4];
    for (int k = 0; k < 4; ++k) {
        const F z = permuted(*vertex[k], shear.kz) - shear.origin_k.z;
        x[k] = (permuted(*vertex[k], shear.kx) - shear.origin_k.x) - shear.sx * z;
        y[k] = (permuted(*vertex[k], shear.ky) - shear.origin_k.y) - shear.sy * z;
    }
    // Edge k -> k+1 as edge_function(v[k+1], v[k]): two rounded products, one difference.
    F e[4];
    for (int k = 0; k < 4; ++k) {
        const int q = (k + 1) % 4;
        e[k] = x[q] * y[k] - y[q] * x[k];
    }
    const Mask on_edge =
        candidates & ((e[0] == 0.0f) | (e[1] == 0.0f) | (e[2] == 0.0f) | (e[3] == 0.0f));
    if (any(on_edge)) redo_quad_edges_exactly(on_edge, x, y, e);
    const Mask any_negative = (e[0] < 0.0f) | (e[1] < 0.0f) | (e[2] < 0.0f) | (e[3] < 0.0f);
    const Mask any_positive = (e[0] > 0.0f) | (e[1] > 0.0f) | (e[2] > 0.0f) | (e[3] > 0.0f);
    const F t = num / denom;
    const Mask hit = and_not(candidates, any_negative & any_positive) & (t > 0.0f) & (t < t_max);
    return select(hit, t, t_max);
    // SKELETON
    //> // TODO(lab02): intersect_quad (common/core/convex_quad.h) in all lanes: as your
    //> // intersect_triangle, with four edge functions (v0v1, v1v2, v2v3, v3v0, each computed
    //> // as the triangle computes the same edge) and the plane's t = num / denom.
    //> // Until then: lane 0 only, with the scalar test.
    //> (void)candidates;
    //> const Ray ray0 = ray.lane(0);
    //> const float t0 = intersect_quad(ray0, RayShear(ray0.direction), quad, t_max.lane(0));
    //> (void)shear;
    //> return select(Mask::first(1), F(t0), t_max);
    // END SOLUTION
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
