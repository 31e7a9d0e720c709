// Axis-aligned rectangle primitive: a quad of the scene file whose four points share one
// coordinate exactly and whose edges are parallel to the other two axes (the walls, floor and
// ceiling of a box). Its test is a division and four sign tests: no shear, no cull.
#pragma once

#include <cmath>

#include <triangle.h>

// Two 16-byte rows (32-byte rows in the double build): the plane and the lower corner, then
// the upper corner and what shading reads. u and v are the two axes other than `axis`, in
// index order (x before y before z).
struct alignas(16) AxisRect {
    // What the scene report calls this kind: one of them (plural: +"s"), its --json key.
    static constexpr const char* kName = "rectangle";
    static constexpr const char* kReportKey = "rects";
    static constexpr bool kShearsRay = false;  // its test takes no RayShear

    real plane;       // the coordinate on `axis` of every point
    real lo_u, lo_v;  // the lower bounds on axes u and v
    real extent;      // largest |coordinate| of the corners: bounds the hit's rounding error
    real hi_u, hi_v;  // the upper bounds, each above its lower one
    int material;     // index into the scene's material table
    int axis_side;    // the axis (0, 1, 2) in bits 0-1; bit 2 set when the front faces -axis
};

RT_HD inline int rect_axis(const AxisRect& r) { return r.axis_side & 3; }
RT_HD inline int rect_axis_u(int axis) { return axis == 0 ? 1 : 0; }
RT_HD inline int rect_axis_v(int axis) { return axis == 2 ? 1 : 2; }

// The vector with `value` on `axis` and zero elsewhere (no indexed store: a GPU would spill).
RT_HD inline Vec3 along_axis(int axis, real value) {
    return {axis == 0 ? value : real(0), axis == 1 ? value : real(0), axis == 2 ? value : real(0)};
}

// Unit geometric normal: toward the front, as a triangle's of the same winding.
RT_HD inline Vec3 rect_normal(const AxisRect& r) {
    return along_axis(rect_axis(r), (r.axis_side & 4) ? real(-1) : real(1));
}

// The axis on which four points (in order) form an axis-aligned rectangle, or -1: they share
// that coordinate exactly, they are the four corners of {lo, hi} x {lo, hi} on the other two
// axes with lo < hi, and each edge changes exactly one coordinate (so they go round the
// rectangle, not across it). Exact comparisons of the points as given.
inline int axis_rect_axis(const Vec3 (&v)[4]) {
    for (int axis = 0; axis < 3; ++axis) {
        if (!(v[0][axis] == v[1][axis] && v[0][axis] == v[2][axis] && v[0][axis] == v[3][axis]))
            continue;
        const int u = rect_axis_u(axis), w = rect_axis_v(axis);
        real lo_u = v[0][u], hi_u = v[0][u], lo_w = v[0][w], hi_w = v[0][w];
        for (const Vec3& p : v) {
            lo_u = min_float(lo_u, p[u]), hi_u = max_float(hi_u, p[u]);
            lo_w = min_float(lo_w, p[w]), hi_w = max_float(hi_w, p[w]);
        }
        if (!(lo_u < hi_u && lo_w < hi_w)) return -1;
        bool corners = true;
        for (int k = 0; k < 4; ++k) {
            const Vec3 &p = v[k], &q = v[(k + 1) % 4];
            const bool on_corner = (p[u] == lo_u || p[u] == hi_u) && (p[w] == lo_w || p[w] == hi_w);
            const bool one_change = (p[u] != q[u]) != (p[w] != q[w]);
            corners = corners && on_corner && one_change;
        }
        return corners ? axis : -1;
    }
    return -1;
}

// Builds the rectangle on `axis` from four corners as axis_rect_axis accepts them; the front
// side is where (v1-v0) x (v2-v0) points, as for a triangle. Host only.
inline AxisRect make_axis_rect(const Vec3 (&v)[4], int axis, int material) {
    const int u = rect_axis_u(axis), w = rect_axis_v(axis);
    AxisRect r;
    r.plane = v[0][axis];
    r.lo_u = r.hi_u = v[0][u];
    r.lo_v = r.hi_v = v[0][w];
    r.extent = 0.0f;
    for (const Vec3& p : v) {
        r.lo_u = min_float(r.lo_u, p[u]), r.hi_u = max_float(r.hi_u, p[u]);
        r.lo_v = min_float(r.lo_v, p[w]), r.hi_v = max_float(r.hi_v, p[w]);
        r.extent = max_float(r.extent, max_component(abs(p)));
    }
    // The winding's normal on `axis`, in double: (v1 - v0) x (v2 - v0), component `axis`.
    const double e1u = double(v[1][u]) - v[0][u], e1w = double(v[1][w]) - v[0][w];
    const double e2u = double(v[2][u]) - v[0][u], e2w = double(v[2][w]) - v[0][w];
    const double along = e1u * e2w - e1w * e2u;  // u before w: a right-handed (u, w, axis)...
    // ...except for axis y, where (u, w) = (x, z) and x cross z is -y.
    const bool front_negative = axis == 1 ? along > 0.0 : along < 0.0;
    r.material = material;
    r.axis_side = axis | (front_negative ? 4 : 0);
    return r;
}

// The corners of the rectangle counter-clockwise seen from its front, from v0 = (lo, lo):
// make_axis_rect of them gives the same rectangle. Host only.
inline void rect_corners(const AxisRect& r, Vec3 (&v)[4]) {
    const int axis = rect_axis(r);
    const int u = rect_axis_u(axis), w = rect_axis_v(axis);
    const auto corner = [&](real cu, real cw) {
        return along_axis(axis, r.plane) + along_axis(u, cu) + along_axis(w, cw);
    };
    // Counter-clockwise around +axis in (u, w) is lo-lo, hi-lo, hi-hi, lo-hi, except for y.
    const bool reversed = ((r.axis_side & 4) != 0) != (axis == 1);
    v[0] = corner(r.lo_u, r.lo_v);
    v[1] = reversed ? corner(r.lo_u, r.hi_v) : corner(r.hi_u, r.lo_v);
    v[2] = corner(r.hi_u, r.hi_v);
    v[3] = reversed ? corner(r.hi_u, r.lo_v) : corner(r.lo_u, r.hi_v);
}

// step_off_edges (triangle.h) for a rectangle: margin along each inward axis for every edge
// that p lies within margin of. Written so that NaN steps off, as the triangle's does.
RT_HD inline Vec3 step_off_edges(const AxisRect& r, Vec3 p, real margin) {
    const int axis = rect_axis(r);
    const int u = rect_axis_u(axis), w = rect_axis_v(axis);
    const real pu = p[u], pw = p[w];
    real step_u = 0.0f, step_w = 0.0f;
    if (!(pu - r.lo_u >= margin)) step_u += margin;
    if (!(r.hi_u - pu >= margin)) step_u -= margin;
    if (!(pw - r.lo_v >= margin)) step_w += margin;
    if (!(r.hi_v - pw >= margin)) step_w -= margin;
    return along_axis(u, step_u) + along_axis(w, step_w);
}

// The canonical 2D edge function of the edge line {p_i = c_i, p_j = c_j} (i < j: the lower
// axis first) as the ray passes it: (c_i - o_i) d_j - (c_j - o_j) d_i, two rounded products
// and a rounded difference (edge_function, never fused). Any rectangle with this edge, in the
// plane p_i = c_i or in p_j = c_j, computes it to the same bits up to its sign (below); it is
// zero where the ray meets the line.
RT_HD inline real canonical_edge(real to_i, real d_i, real to_j, real d_j) {
    return edge_function(to_i, to_j, d_i, d_j);
}

// The rectangle's four edge lines as the ray crosses its plane: whether the crossing lies on
// the inner side of every one. For the edge at c on axis `other`, u_hit - c is
// canonical_edge(...) / d_a when a comes before `other`, its negation otherwise; both are
//     (to_plane * sign(d_a)) * d_other - (c - o_other) * |d_a|,   divided by |d_a|,
// since multiplying by +-1 is exact and a rounded difference changes sign exactly with its
// operands. That form reads every sign without a division and without a multiplication by the
// sign per edge, and it is still canonical_edge bit for bit up to the sign, so two rectangles
// that share an edge compute it identically and read it oppositely: a ray through the edge
// passes the test of at least one (both on the line). NaN fails every comparison.
RT_HD RT_FORCE_INLINE bool rect_contains_crossing(const Ray& ray, const AxisRect& r,
                                                  real to_plane_signed, real d_a_abs, const int a) {
    const int u = rect_axis_u(a), w = rect_axis_v(a);
    const real d_u = ray.direction[u], d_w = ray.direction[w];
    const real o_u = ray.origin[u], o_w = ray.origin[w];
    const auto from_edge = [&](real to_edge, real d_other) {  // (u_hit - c) * |d_a|
        return edge_function(to_plane_signed, to_edge, d_a_abs, d_other);
    };
    return (from_edge(r.lo_u - o_u, d_u) >= 0.0f) & (from_edge(r.hi_u - o_u, d_u) <= 0.0f) &
           (from_edge(r.lo_v - o_w, d_w) >= 0.0f) & (from_edge(r.hi_v - o_w, d_w) <= 0.0f);
}

// Ray/rectangle intersection: t = (plane - o_a) / d_a, and the hit lies inside when it is on
// the inner side of each of the four edge lines (rect_contains_crossing). A ray parallel to
// the plane misses. Returns the distance in (0, t_max), or t_max for a miss.
//
// rect_test_on_axis is that test with the axis `a` as an argument; intersect_rect passes the
// rectangle's. On a GPU every lane of a warp tests the same rectangle, so a branch on its axis
// is taken by the whole warp, and each branch's copy of the test, inlined with `a` a constant,
// reads ray.direction.x rather than choosing among x, y and z at every access (a runtime index
// into a Vec3 is two selects per read on a GPU). A CPU indexes memory at no cost and keeps one
// copy. The same operations either way: the same bits.
template <bool kConverged>
RT_HD RT_FORCE_INLINE real rect_test_on_axis(const Ray& ray, const AxisRect& r, real t_max,
                                             const int a) {
    const real d_a = ray.direction[a];
    const real to_plane = r.plane - ray.origin[a];
    const real t = to_plane / d_a;
    const bool in_range = (t > 0.0f) & (t < t_max) & (fabs_real(d_a) > 0.0f);  // NaN fails
    // Converged, only when no lane of the warp has the plane in range: otherwise the final
    // select decides.
    if (kConverged ? !any_lane(in_range) : !in_range) return t_max;
    const real to_plane_signed = to_plane * copysign_real(real(1), d_a);
    const bool inside = rect_contains_crossing(ray, r, to_plane_signed, fabs_real(d_a), a);
    return (in_range & inside) ? t : t_max;
}

// Whether the rectangle lies on the ray before t_max: intersect_rect(...) < t_max, the same
// answer for every ray, for a shadow ray. It culls before it divides: a shadow ray inside a
// room meets no wall before the light, so on a GPU most warps then skip the division too. The
// cull only rejects what the test rejects: t > 0 needs to_plane * sign(d_a) > 0, and t < t_max
// needs to_plane * sign(d_a) < t_max |d_a|, which the bound exceeds by its 1e-5 margin
// (and by kRealMin where the product would round below the normal floats).
template <bool kConverged>
RT_HD RT_FORCE_INLINE bool rect_blocks_on_axis(const Ray& ray, const AxisRect& r, real t_max,
                                               const int a) {
    const real d_a = ray.direction[a];
    const real d_a_abs = fabs_real(d_a);
    const real to_plane = r.plane - ray.origin[a];
    const real to_plane_signed = to_plane * copysign_real(real(1), d_a);
    const real bound = max_float(t_max * real(1.00001f) * d_a_abs, kRealMin);
    const bool culled = !(to_plane_signed > 0.0f) | (to_plane_signed >= bound);
    if (kConverged ? !any_lane(!culled) : culled) return false;
    const real t = to_plane / d_a;
    const bool in_range = (t > 0.0f) & (t < t_max) & (d_a_abs > 0.0f);
    return in_range & rect_contains_crossing(ray, r, to_plane_signed, d_a_abs, a);
}

template <bool kConverged = kConvergedTests>  // rt_hd.h
RT_HD inline real intersect_rect(const Ray& ray, const AxisRect& r, real t_max) {
    const int a = rect_axis(r);
    if constexpr (kConverged) {
        switch (a) {
            case 0: return rect_test_on_axis<kConverged>(ray, r, t_max, 0);
            case 1: return rect_test_on_axis<kConverged>(ray, r, t_max, 1);
            case 2: return rect_test_on_axis<kConverged>(ray, r, t_max, 2);
            default: return t_max;  // no rectangle has axis 3 (make_axis_rect)
        }
    }
    return rect_test_on_axis<kConverged>(ray, r, t_max, a);
}
template <bool kConverged = kConvergedTests>  // rt_hd.h
RT_HD inline bool rect_blocks(const Ray& ray, const AxisRect& r, real t_max) {
    const int a = rect_axis(r);
    if constexpr (kConverged) {
        switch (a) {
            case 0: return rect_blocks_on_axis<kConverged>(ray, r, t_max, 0);
            case 1: return rect_blocks_on_axis<kConverged>(ray, r, t_max, 1);
            case 2: return rect_blocks_on_axis<kConverged>(ray, r, t_max, 2);
            default: return false;
        }
    }
    return rect_blocks_on_axis<kConverged>(ray, r, t_max, a);
}

// The kind's hooks (primitive_kinds.h); step_off_edges is above.
template <bool kConverged = kConvergedTests>
RT_HD inline real intersect(const Ray& ray, const AxisRect& r, real t_max) {
    return intersect_rect<kConverged>(ray, r, t_max);
}
template <bool kConverged = kConvergedTests>
RT_HD inline bool occludes(const Ray& ray, const AxisRect& r, real t_max) {
    return rect_blocks<kConverged>(ray, r, t_max);
}
RT_HD inline Vec3 normal_at(const AxisRect& r, Vec3) { return rect_normal(r); }
RT_HD inline real surface_extent(const AxisRect& r) { return r.extent; }
