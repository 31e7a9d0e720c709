// Planar convex quadrilateral primitive and its watertight ray intersection. A quad of the
// scene file whose four points are coplanar and convex (every parallelogram is) is one of
// these instead of two triangles: one plane cull and four edge functions instead of two culls
// and six, and one primitive fewer for every loop to visit.
#pragma once

#include <cmath>

#include <triangle.h>

// Five 16-byte rows (32-byte rows in the double build), as Triangle's: the cull's normal and
// plane offset first, then one vertex per row. The vertices are the four written ones,
// rounded once, so an edge shared with a triangle or another quad has the same float
// endpoints on both sides.
struct alignas(16) ConvexQuad {
    // What the scene report calls this kind: one of them (plural: +"s"), its --json key.
    static constexpr const char* kName = "convex quad";
    static constexpr const char* kReportKey = "quads";
    static constexpr bool kShearsRay = true;  // its test takes the ray's RayShear

    Vec3 normal;        // unit normal of the fitted plane; the front side as a triangle's
    real plane_offset;  // the plane is dot(normal, p) == plane_offset
    Vec3 v0;            // vertices, counter-clockwise seen from the front
    real extent;        // largest |coordinate| of the vertices: bounds the hit's rounding error
    Vec3 v1;
    int material;  // index into the scene's material table
    Vec3 v2;
    int cut_edges = 0;  // bit k: edge k (v_k to v_k+1) is a cut (triangle.h's step_off_cut_edge);
        // it also fills the row (lab 02 reads 16 bytes at each vertex)
    Vec3 v3;
    real unused3 = 0;
};

// Builds the quad with the plane that fits its vertices best, computed in double (see
// make_triangle): the normal is that of the diagonals' cross product (v2-v0) x (v3-v1), which
// points to the front for a counter-clockwise quad and weighs the four vertices alike, and the
// plane passes through their mean. Host only.
inline ConvexQuad make_convex_quad(Vec3 v0, Vec3 v1, Vec3 v2, Vec3 v3, int material) {
    const double d1[3] = {double(v2.x) - v0.x, double(v2.y) - v0.y, double(v2.z) - v0.z};
    const double d2[3] = {double(v3.x) - v1.x, double(v3.y) - v1.y, double(v3.z) - v1.z};
    const double n[3] = {d1[1] * d2[2] - d1[2] * d2[1], d1[2] * d2[0] - d1[0] * d2[2],
                         d1[0] * d2[1] - d1[1] * d2[0]};
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const Vec3 normal = len > 0.0
                            ? Vec3(static_cast<real>(n[0] / len), static_cast<real>(n[1] / len),
                                   static_cast<real>(n[2] / len))
                            : Vec3(0.0f);
    const Vec3 v[4] = {v0, v1, v2, v3};
    double offset = 0.0;
    real extent = 0.0f;
    for (const Vec3& p : v) {
        offset += double(normal.x) * p.x + double(normal.y) * p.y + double(normal.z) * p.z;
        extent = max_float(extent, max_component(abs(p)));
    }
    ConvexQuad quad;
    quad.normal = normal;
    quad.plane_offset = static_cast<real>(offset / 4.0);
    quad.v0 = v0;
    quad.extent = extent;
    quad.v1 = v1;
    quad.material = material;
    quad.v2 = v2;
    quad.v3 = v3;
    return quad;
}

// Whether four points (in order) are one planar convex quad to within the rounding of their
// coordinates: every vertex lies within 4 units in the last place of the quad's extent from
// the plane of make_convex_quad (a parallelogram written exactly in decimal and rounded to
// `real` is off by less than one), and every corner turns the same way, strictly (three points
// on a line, or a quad with no area, stay two triangles). In double, on the points as given.
inline bool is_planar_convex_quad(const Vec3 (&v)[4]) {
    double p[4][3];
    double extent = 0.0;
    for (int k = 0; k < 4; ++k) {
        p[k][0] = v[k].x, p[k][1] = v[k].y, p[k][2] = v[k].z;
        for (double c : p[k]) extent = std::fmax(extent, std::fabs(c));
    }
    const auto sub = [](const double* a, const double* b, double* out) {
        for (int i = 0; i < 3; ++i) out[i] = a[i] - b[i];
    };
    const auto cross3 = [](const double* a, const double* b, double* out) {
        out[0] = a[1] * b[2] - a[2] * b[1];
        out[1] = a[2] * b[0] - a[0] * b[2];
        out[2] = a[0] * b[1] - a[1] * b[0];
    };
    double d1[3], d2[3], n[3];
    sub(p[2], p[0], d1);
    sub(p[3], p[1], d2);
    cross3(d1, d2, n);
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    if (!(len > 0.0)) return false;
    for (double& c : n) c /= len;
    double mean = 0.0;
    for (const auto& q : p) mean += n[0] * q[0] + n[1] * q[1] + n[2] * q[2];
    mean /= 4.0;
    const double tolerance = 4.0 * kRealEpsilon * extent;
    for (const auto& q : p) {
        if (!(std::fabs(n[0] * q[0] + n[1] * q[1] + n[2] * q[2] - mean) <= tolerance)) return false;
    }
    for (int k = 0; k < 4; ++k) {  // the turn at vertex k+1, against the normal
        double e1[3], e2[3], turn[3];
        sub(p[(k + 1) % 4], p[k], e1);
        sub(p[(k + 2) % 4], p[(k + 1) % 4], e2);
        cross3(e1, e2, turn);
        if (!(n[0] * turn[0] + n[1] * turn[1] + n[2] * turn[2] > 0.0)) return false;
    }
    return true;
}

// step_off_edges (triangle.h) for the quad's four edges.
RT_HD inline Vec3 step_off_edges(const ConvexQuad& quad, Vec3 p, real margin) {
    Vec3 step(0.0f);
    step_off_edge(quad.normal, quad.v0, quad.v1, p, margin, step);
    step_off_edge(quad.normal, quad.v1, quad.v2, p, margin, step);
    step_off_edge(quad.normal, quad.v2, quad.v3, p, margin, step);
    step_off_edge(quad.normal, quad.v3, quad.v0, p, margin, step);
    return step;
}
// With the arriving ray's direction, for the cut edges of cut_edges (triangle.h's).
RT_HD inline Vec3 step_off_edges(const ConvexQuad& quad, Vec3 p, real margin, Vec3 direction) {
    if (quad.cut_edges == 0) return step_off_edges(quad, p, margin);
    Vec3 step(0.0f);
    const Vec3 v[4] = {quad.v0, quad.v1, quad.v2, quad.v3};
    for (int k = 0; k < 4; ++k) {
        if (quad.cut_edges & (1 << k))
            step_off_cut_edge(quad.normal, v[k], v[(k + 1) % 4], p, margin, direction, step);
        else step_off_edge(quad.normal, v[k], v[(k + 1) % 4], p, margin, step);
    }
    return step;
}

// Watertight ray/quad intersection: the triangle's plane cull (plane_culled), then its ray-space
// edge functions, one per edge v0v1, v1v2, v2v3, v3v0, each computed as the triangle's of the same
// directed edge (edge_function of the vertices shear_vertex gives, the same operand order). A
// triangle or quad across a shared edge (the same float endpoints) computes exactly the negated
// value, so a ray through the edge hits at least one of the two. The ray passes inside when no two
// edge functions have opposite signs (the quad is convex); the distance is then the plane's,
// num / denom of the cull. Returns the distance in (0, t_max), or t_max for a miss; rays parallel
// to the plane, quads with no area and NaN miss.
template <bool kConverged = kConvergedTests>  // rt_hd.h
RT_HD inline real intersect_quad(const Ray& ray, const RayShear& shear, const ConvexQuad& quad,
                                 real t_max) {
    const real denom = dot(quad.normal, ray.direction);
    const real num = quad.plane_offset - dot(quad.normal, ray.origin);
    const bool culled = plane_culled(num, denom, t_max);
    // Converged, the warp skips the rest when every lane's cull rejects the primitive (the
    // same answer, t_max, on every lane), and runs it on all of them otherwise.
    if (kConverged ? !any_lane(!culled) : culled) return t_max;

    const ShearedVertex a = shear_vertex(quad.v0, ray, shear);
    const ShearedVertex b = shear_vertex(quad.v1, ray, shear);
    const ShearedVertex c = shear_vertex(quad.v2, ray, shear);
    const ShearedVertex d = shear_vertex(quad.v3, ray, shear);

    // Edge p -> q as the triangle computes it: edge_function(q, p) (its w is v0v1's).
    real e01 = edge_function(b.x, b.y, a.x, a.y);
    real e12 = edge_function(c.x, c.y, b.x, b.y);
    real e23 = edge_function(d.x, d.y, c.x, c.y);
    real e30 = edge_function(a.x, a.y, d.x, d.y);
    if (!culled && (e01 == 0.0f || e12 == 0.0f || e23 == 0.0f || e30 == 0.0f)) {  // rare
        e01 = static_cast<real>(edge_function_exact(b.x, b.y, a.x, a.y));
        e12 = static_cast<real>(edge_function_exact(c.x, c.y, b.x, b.y));
        e23 = static_cast<real>(edge_function_exact(d.x, d.y, c.x, c.y));
        e30 = static_cast<real>(edge_function_exact(a.x, a.y, d.x, d.y));
    }
    const bool any_negative = (e01 < 0.0f) | (e12 < 0.0f) | (e23 < 0.0f) | (e30 < 0.0f);
    const bool any_positive = (e01 > 0.0f) | (e12 > 0.0f) | (e23 > 0.0f) | (e30 > 0.0f);
    const bool outside = any_negative & any_positive;  // the ray passes outside an edge
    if (!kConverged && outside) return t_max;

    const real t = num / denom;
    const bool hit = !(culled | outside) & (t > 0.0f) & (t < t_max);  // NaN fails too
    return hit ? t : t_max;
}

// The kind's hooks (primitive_kinds.h); step_off_edges is above.
template <bool kConverged = kConvergedTests>
RT_HD inline real intersect(const Ray& ray, const RayShear& shear, const ConvexQuad& quad,
                            real t_max) {
    return intersect_quad<kConverged>(ray, shear, quad, t_max);
}
template <bool kConverged = kConvergedTests>
RT_HD inline bool occludes(const Ray& ray, const RayShear& shear, const ConvexQuad& quad,
                           real t_max) {
    return intersect_quad<kConverged>(ray, shear, quad, t_max) < t_max;
}
RT_HD inline Vec3 normal_at(const ConvexQuad& quad, Vec3) { return quad.normal; }
RT_HD inline real surface_extent(const ConvexQuad& quad) { return quad.extent; }
