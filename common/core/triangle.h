// Triangle primitive and watertight ray intersection.
#pragma once

#include <cmath>

#include <ray.h>

// Four 16-byte rows (32-byte rows in the double build), 16-byte aligned: what the cheap cull
// reads (normal and plane offset) is the first row, each vertex starts a row. A GPU then
// loads a row with one vector load (one LDS.128 from shared memory instead of four scalar
// loads: the megakernel is bound by instruction issue), and a CPU finds the whole triangle
// in one 64-byte cache line.
struct alignas(16) Triangle {
    // What the scene report calls this kind: one of them (plural: +"s"), its --json key.
    static constexpr const char* kName = "triangle";
    static constexpr const char* kReportKey = "triangles";
    static constexpr bool kShearsRay = true;  // its test takes the ray's RayShear

    Vec3 normal;         // unit geometric normal, or zero for a degenerate triangle
    real plane_offset;   // dot(normal, v0): the plane is dot(normal, p) == plane_offset
    Vec3 v0;             // vertices; the front side is where (v1-v0) x (v2-v0) points
    real extent;         // largest |coordinate| of the vertices: bounds the hit's rounding error
    Vec3 v1;
    int material;        // index into the scene's material table
    Vec3 v2;
    int cut_edges = 0;  // bit k: edge k (v_k to v_k+1) is a cut (step_off_cut_edge); it also
                        // fills the last row (lab 02 reads 16 bytes at each vertex)
};

// Builds a triangle with its normal; a zero-area triangle gets a zero normal and is never hit.
// The normal is computed in double: in float, |(v1-v0) x (v2-v0)|^2 grows as the edge length
// to the fourth power, so it overflows for edges past ~1e9 and underflows below ~1e-11, and
// the triangle silently vanished. Double holds that square for any float vertices. Host only:
// scenes are built before rendering. (In the double build the vertices are doubles too, and
// the square still overflows only past edges of ~1e77, far beyond scene_limits.h's bounds.)
inline Triangle make_triangle(Vec3 v0, Vec3 v1, Vec3 v2, int material) {
    const double e1[3] = {double(v1.x) - v0.x, double(v1.y) - v0.y, double(v1.z) - v0.z};
    const double e2[3] = {double(v2.x) - v0.x, double(v2.y) - v0.y, double(v2.z) - v0.z};
    const double n[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                         e1[0] * e2[1] - e1[1] * e2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const Vec3 normal = len > 0.0
                            ? Vec3(static_cast<real>(n[0] / len), static_cast<real>(n[1] / len),
                                   static_cast<real>(n[2] / len))
                            : Vec3(0.0f);
    // The plane of the stored (real) normal through v0, rounded once.
    const real plane_offset = static_cast<real>(double(normal.x) * v0.x + double(normal.y) * v0.y +
                                                double(normal.z) * v0.z);
    const real extent = max_float(max_component(abs(v0)),
                                  max_float(max_component(abs(v1)), max_component(abs(v2))));
    Triangle tri;
    tri.normal = normal;
    tri.plane_offset = plane_offset;
    tri.v0 = v0;
    tri.extent = extent;
    tri.v1 = v1;
    tri.material = material;
    tri.v2 = v2;
    return tri;
}

// A point of a triangle that lies on one of its edges (or within rounding of it) lies on the
// neighbouring face's plane too: at a closed room's corner, the face across the edge. A ray
// offset along this triangle's normal alone (ray.h) leaves this plane but not that one, so the
// next ray may start just behind the neighbour, pass through it, and leave the room (a closed
// mirror cube lost one path in 368,640 that way at 64 bounces). step_off_edges is the step,
// within the triangle's plane, that also takes p `margin` inside every edge nearer than that:
// for each such edge, `margin` along its inward perpendicular. With the normal offset, the
// origin then lies in front of every face that meets this one at an edge at more than 45
// degrees, as a room's walls do. Zero for a point farther than `margin` from every edge.
RT_HD inline void step_off_edge(Vec3 normal, Vec3 from, Vec3 to, Vec3 p, real margin, Vec3& step) {
    const Vec3 inward = cross(normal, to - from);  // in the plane, toward the inside
    const real inward_length = length(inward);     // the edge's length
    const real depth = dot(p - from, inward);      // distance inside the edge x inward_length
    if (!(depth >= margin * inward_length)) step += inward * (margin / inward_length);
}
RT_HD inline Vec3 step_off_edges(const Triangle& tri, Vec3 p, real margin) {
    Vec3 step(0.0f);
    step_off_edge(tri.normal, tri.v0, tri.v1, p, margin, step);
    step_off_edge(tri.normal, tri.v1, tri.v2, p, margin, step);
    step_off_edge(tri.normal, tri.v2, tri.v0, p, margin, step);
    return step;
}

// A cut edge (the loader's, t_junctions.h) is one this face shares end to end with a piece of
// its own plane, where a third face meets both: a wall cut along a ceiling's edge that lies
// inside it. Near such an edge the inward step is wrong half the time: a ray from the room
// below the ceiling that the rounding lets hit the wall's part above it (the ceiling and that
// part are hit together there, at distances that differ by rounding) was stepped up into that
// part, behind the ceiling, and left the room. So at a cut edge the step goes to the side the
// ray came from (`direction` is the arriving ray's): inward when it travels toward the edge,
// else 2 margins across it, so that p ends at least `margin` inside the partner. The side of
// the edge the ray came from is the side of the third face's plane it came from where that
// face is square to this one, as a room's ceiling is to its walls.
RT_HD inline void step_off_cut_edge(Vec3 normal, Vec3 from, Vec3 to, Vec3 p, real margin,
                                    Vec3 direction, Vec3& step) {
    const Vec3 inward = cross(normal, to - from);
    const real inward_length = length(inward);
    const real depth = dot(p - from, inward);
    if (depth >= margin * inward_length) return;  // NaN steps, as step_off_edge's does
    const bool across = dot(direction, inward) > 0.0f;  // it came from the partner's side
    step += inward * ((across ? real(-2) * margin : margin) / inward_length);
}
// step_off_edges with the arriving ray's direction, for the cut edges of cut_edges; the same
// bits as step_off_edges where there are none.
RT_HD inline Vec3 step_off_edges(const Triangle& tri, Vec3 p, real margin, Vec3 direction) {
    if (tri.cut_edges == 0) return step_off_edges(tri, p, margin);
    Vec3 step(0.0f);
    const Vec3 v[3] = {tri.v0, tri.v1, tri.v2};
    for (int k = 0; k < 3; ++k) {
        if (tri.cut_edges & (1 << k))
            step_off_cut_edge(tri.normal, v[k], v[(k + 1) % 3], p, margin, direction, step);
        else step_off_edge(tri.normal, v[k], v[(k + 1) % 3], p, margin, step);
    }
    return step;
}

// Per-ray constants of the watertight test: the axis permutation that makes the ray's
// dominant axis z, and the shear that maps the ray onto +z.
struct RayShear {
    int kx, ky, kz;  // permuted axes
    real sx, sy;     // shear constants: d[kx] / d[kz], d[ky] / d[kz]

    RT_HD explicit RayShear(Vec3 d) {
        const Vec3 a = abs(d);
        kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
        kx = kz == 2 ? 0 : kz + 1;
        ky = kx == 2 ? 0 : kx + 1;
        if (d[kz] < 0.0f) {  // keep the winding so the sign of det tells front from back
            const int tmp = kx;
            kx = ky;
            ky = tmp;
        }
        const real sz = real(1) / d[kz];
        sx = d[kx] * sz;
        sy = d[ky] * sz;
    }
};

// A vertex in the ray's sheared space: relative to the origin, its axes permuted by the
// RayShear and sheared so that the ray runs along +z. z is left unscaled (the tests take the
// distance from the plane). Triangles and quads that share a vertex get the same bits for it.
struct ShearedVertex {
    real x, y, z;
};
RT_HD RT_FORCE_INLINE ShearedVertex shear_vertex(Vec3 vertex, const Ray& ray,
                                                 const RayShear& shear) {
    const Vec3 a = vertex - ray.origin;
    const real z = a[shear.kz];
    return {a[shear.kx] - shear.sx * z, a[shear.ky] - shear.sy * z, z};
}

// The cheap cull both sheared tests start with (intersect_triangle, intersect_quad), from the
// plane's distance along the ray, num / denom (denom = normal . direction): whether the plane lies
// behind the ray or clearly beyond t_max (ten times fewer flops than the full test; most primitives
// of a closed room end here). It only rejects, never accepts, so the watertight test still decides
// every hit; the 1e-5 margin keeps rounding from culling a hit right at t_max. Parallel rays and
// degenerate primitives (zero normal) have denom == 0 and are culled too, and so is NaN. Bitwise |
// rather than ||: one well-predicted branch instead of several random ones; on a GPU the lanes that
// passed the cull still run the test together with those that did not, whose cull joins the final
// select (kConvergedTests, rt_hd.h).
RT_HD RT_FORCE_INLINE bool plane_culled(real num, real denom, real t_max) {
    const bool behind = !(num * denom > 0.0f);
    const bool beyond = fabs_real(num) >= t_max * real(1.00001f) * fabs_real(denom);
    return behind | beyond;
}

// 2D edge function of directed edge p -> q as seen from the ray: twice the signed area of
// (origin, p, q). Computed as two rounded products and one rounded difference, never fused:
// then the neighbour that shares the edge gets exactly the negated value, which is what makes
// the test watertight (a ray through a shared edge hits at least one of the two triangles).
// Host code is built with -ffp-contract=off; on the GPU the _rn intrinsics forbid fusing.
RT_HD inline float edge_function(float px, float py, float qx, float qy) {
#if defined(__CUDA_ARCH__)
    return __fsub_rn(__fmul_rn(px, qy), __fmul_rn(py, qx));
#else
    return px * qy - py * qx;
#endif
}
RT_HD inline double edge_function(double px, double py, double qx, double qy) {
#if defined(__CUDA_ARCH__)
    return __dsub_rn(__dmul_rn(px, qy), __dmul_rn(py, qx));
#else
    return px * qy - py * qx;
#endif
}

// The same in double, where float products are exact: the sign is exact even when the
// float result rounds to zero.
RT_HD inline double edge_function_exact(float px, float py, float qx, float qy) {
    return static_cast<double>(px) * qy - static_cast<double>(py) * qx;
}

// The double build's fallback. There is no wider type to make double products exact on the
// GPU (long double is host only, and its 64-bit significand is not enough for them either),
// so each product is split exactly into its rounded value and its rounding error with an FMA
// (p = a*b, e = fma(a, b, -p)), and the edge function is (p1 - p2) + (e1 - e2). Its sign is
// the exact sign or the value is zero (an edge hit), and swapping p and q negates every step
// exactly, so the neighbour across the edge gets exactly the negated value: still watertight.
// The products use the _rn intrinsics on the GPU so that nvcc cannot fuse p1 into p1 - p2.
RT_HD inline double edge_function_exact(double px, double py, double qx, double qy) {
#if defined(__CUDA_ARCH__)
    const double p1 = __dmul_rn(px, qy), p2 = __dmul_rn(py, qx);
#else
    const double p1 = px * qy, p2 = py * qx;
#endif
    const double e1 = fma(px, qy, -p1), e2 = fma(py, qx, -p2);
    return (p1 - p2) + (e1 - e2);
}

// Watertight ray/triangle intersection (Woop, Benthin, Wald, JCGT 2013) for whether the ray
// passes inside; the distance is the plane's, num / denom of the cull, as the quad's
// (convex_quad.h). Woop's own distance, the barycentric mix of the vertices' distances
// (u az + v bz + w cz) / det, errs by the edge functions' rounding over det: about the
// triangle's aspect ratio times an ulp of its extent. For the needles of a fan around a disk
// that is several ray offsets (ray.h), so a hit point could land under the surface, and its
// shadow ray hit the disk again, in double as in float (docs/extremes.md). The plane's
// distance errs by a few ulps of the plane's offset and the origin, whatever the shape: across
// the plane, the hit point lies within the offset that extent and |p| bound. Returns the
// distance in (0, t_max), or t_max for a miss. Rays parallel to the triangle's plane and
// degenerate triangles give det == 0 (or denom == 0) and miss.
template <bool kConverged = kConvergedTests>  // rt_hd.h
RT_HD inline real intersect_triangle(const Ray& ray, const RayShear& shear, const Triangle& tri,
                                     real t_max) {
    const real denom = dot(tri.normal, ray.direction);
    const real num = tri.plane_offset - dot(tri.normal, ray.origin);  // t_plane = num / denom
    const bool culled = plane_culled(num, denom, t_max);
    // Converged, the warp skips the rest when every lane's cull rejects the primitive (the
    // same answer, t_max, on every lane), and runs it on all of them otherwise.
    if (kConverged ? !any_lane(!culled) : culled) return t_max;

    const ShearedVertex a = shear_vertex(tri.v0, ray, shear);
    const ShearedVertex b = shear_vertex(tri.v1, ray, shear);
    const ShearedVertex c = shear_vertex(tri.v2, ray, shear);

    real u = edge_function(c.x, c.y, b.x, b.y);
    real v = edge_function(a.x, a.y, c.x, c.y);
    real w = edge_function(b.x, b.y, a.x, a.y);
    if (!culled && (u == 0.0f || v == 0.0f || w == 0.0f)) {  // rare: on an edge, or rounded
        u = static_cast<real>(edge_function_exact(c.x, c.y, b.x, b.y));
        v = static_cast<real>(edge_function_exact(a.x, a.y, c.x, c.y));
        w = static_cast<real>(edge_function_exact(b.x, b.y, a.x, a.y));
    }
    const bool any_negative = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    const bool any_positive = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    const bool outside = any_negative & any_positive;  // the ray passes outside an edge
    if (!kConverged && outside) return t_max;

    const real det = u + v + w;  // 0 for a parallel ray or a degenerate triangle: a miss
    // Divided before the select: written inside it, the division becomes a branch on a GPU.
    const real t = num / denom;
    const bool hit = !(culled | outside) & (det != 0.0f) & (t > 0.0f) & (t < t_max);  // NaN fails
    return hit ? t : t_max;
}

// The kind's hooks (primitive_kinds.h).
template <bool kConverged = kConvergedTests>
RT_HD inline real intersect(const Ray& ray, const RayShear& shear, const Triangle& tri,
                            real t_max) {
    return intersect_triangle<kConverged>(ray, shear, tri, t_max);
}
template <bool kConverged = kConvergedTests>
RT_HD inline bool occludes(const Ray& ray, const RayShear& shear, const Triangle& tri, real t_max) {
    return intersect_triangle<kConverged>(ray, shear, tri, t_max) < t_max;
}
RT_HD inline Vec3 normal_at(const Triangle& tri, Vec3) { return tri.normal; }
RT_HD inline real surface_extent(const Triangle& tri) { return tri.extent; }
