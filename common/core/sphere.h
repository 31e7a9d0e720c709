// Sphere primitive and its numerically stable ray intersection.
#pragma once

#include <cmath>

#include <file_fields.h>
#include <kinds.h>
#include <ray.h>

// 16-byte aligned, centre and radius in the first row: the intersection test reads them with
// one vector load on a GPU (see Triangle).
struct alignas(16) Sphere {
    // What the scene report calls this kind: one of them (plural: +"s"), its --json key.
    static constexpr const char* kName = "sphere";
    static constexpr const char* kReportKey = "spheres";
    static constexpr bool kShearsRay = false;  // its test takes no RayShear
    // Its entry in a scene file (file_fields.h): under "spheres", a centre and a radius.
    static constexpr const char* kFileKey = "spheres";
    static constexpr FileField kFields[] = {{"center", FieldRole::Point},
                                            {"radius", FieldRole::Length}};

    Vec3 center;    // world-space centre
    real radius;    // > 0
    int material;   // index into the scene's material table
};

// The largest coordinate magnitude on the sphere: what its intersection's rounding error
// grows with (offset_ray_origin in ray.h).
RT_HD inline real sphere_extent(const Sphere& s) { return max_component(abs(s.center)) + s.radius; }

// Distance along `ray` to the nearest intersection with `s` in (0, t_max), or t_max when
// there is none. Avoids both cancellations of the textbook b^2 - 4ac form:
//  - the discriminant is r^2 - |f - (f.d)d|^2 (the squared distance from the centre to the
//    ray), not b^2 - c, which loses every digit when the sphere is far away or small;
//  - the near root is c / q with q = b + sign(b) sqrt(disc), not b - sqrt(disc)
//    (Haines et al., "Precision Improvements for Ray/Sphere Intersection", Ray Tracing Gems).
template <bool kConverged = kConvergedTests>  // rt_hd.h
RT_HD inline real intersect_sphere(const Ray& ray, const Sphere& s, real t_max) {
    const Vec3 f = ray.origin - s.center;
    const real b = -dot(f, ray.direction);  // the ray passes closest to the centre at t = b
    const Vec3 perpendicular = f + ray.direction * b;  // centre-to-ray offset at that point
    const real r2 = s.radius * s.radius;
    const real disc = r2 - length_squared(perpendicular);
    const bool meets = disc >= 0.0f;  // false for NaN too
    // Converged, only when the line misses the sphere on every lane of the warp; otherwise
    // the final select decides.
    if (kConverged ? !any_lane(meets) : !meets) return t_max;
    // A GPU's miss goes on with the root of 1, whatever it is worth: the root of a negative
    // number, or of 0, would take the slow path of its square root.
    const real q = b + copysign_real(sqrt_real(meets ? disc : real(1)), b);
    const real c = length_squared(f) - r2;
    const real t_a = c / q;
    const real t_b = q;
    const real t_near = min_float(t_a, t_b);
    const real t_far = max_float(t_a, t_b);
    const bool near_ok = (t_near > 0.0f) & (t_near < t_max);
    const bool far_ok = (t_far > 0.0f) & (t_far < t_max);
    return !meets ? t_max : near_ok ? t_near : far_ok ? t_far : t_max;
}

// The kind's hooks (primitive_kinds.h).
template <bool kConverged = kConvergedTests>
RT_HD inline real intersect(const Ray& ray, const Sphere& s, real t_max) {
    return intersect_sphere<kConverged>(ray, s, t_max);
}
template <bool kConverged = kConvergedTests>
RT_HD inline bool occludes(const Ray& ray, const Sphere& s, real t_max) {
    return intersect_sphere<kConverged>(ray, s, t_max) < t_max;
}
RT_HD inline Vec3 normal_at(const Sphere& s, Vec3 p) { return normalize(p - s.center); }
RT_HD inline real surface_extent(const Sphere& s) { return sphere_extent(s); }
RT_HD inline Vec3 step_off_edges(const Sphere&, Vec3, real) { return Vec3(0.0f); }  // no edges

// Its entry's values (file_fields.h): the centre's three, then the radius.
inline Sphere from_fields(KindTag<Sphere>, const real* v, int material) {
    return {Vec3(v[0], v[1], v[2]), v[3], material};
}
inline void fields_of(const Sphere& s, real* v) {
    v[0] = s.center.x;
    v[1] = s.center.y;
    v[2] = s.center.z;
    v[3] = s.radius;
}
