// GENERATED from common/path_tracer.h by tools/skeletons.py: edit this file freely,
// it is yours. (Instructors: edit the solution and run `make skeletons`.)
// The path tracer every lab shares: the primitive loops (closest hit, shadow test), the path
// loop with next-event estimation, and the per-pixel estimator.
//
// The path loop is written once for any Geometry: a type for which closest_hit(geometry, ray)
// and occluded(geometry, ray, t_max) exist. Lab 01's geometry is the SceneView itself (the
// brute-force loops below); lab 02 supplies an 8-wide AVX2 one. Likewise any Rng with
// `float at(uint32_t dimension) const` will do; the labs use SampleStream.
//
// Lab 01 students write the regions between BEGIN/END SOLUTION; the skeleton generator
// (tools/skeletons.py) turns this file into labs/01-serial/skeleton/path_tracer.h.
#pragma once

#include <cfloat>

#include "rng.h"
#include "sample_sum.h"
#include "scene.h"

// The nearest surface a ray meets: which primitive and how far.
struct Hit {
    float t = FLT_MAX;  // distance along the ray; FLT_MAX when nothing was hit
    int sphere = -1;    // index of the sphere hit, or -1
    int triangle = -1;  // index of the triangle hit, or -1

    RT_HD bool found() const { return sphere >= 0 || triangle >= 0; }
};

// What shading needs to know about a hit point.
struct SurfacePoint {
    Vec3 position;  // world-space hit point
    Vec3 normal;    // unit geometric normal: outward for spheres, the front side for triangles
    int material;   // index into the material table
};

RT_HD inline SurfacePoint surface_at(const SceneView& scene, const Ray& ray, const Hit& hit) {
    const Vec3 p = ray.at(hit.t);
    if (hit.sphere >= 0) {
        const Sphere& s = scene.spheres[hit.sphere];
        return {p, normalize(p - s.center), s.material};
    }
    const Triangle& tri = scene.triangles[hit.triangle];
    return {p, tri.normal, tri.material};
}

// Closest hit by brute force over every primitive: the scenes of this course are small.
RT_HD inline Hit closest_hit(const SceneView& scene, const Ray& ray) {
    Hit hit;
    // TODO(lab01): this finds spheres only. Loop over the triangles too (build one
    // RayShear per ray, then intersect_triangle), keeping the nearest hit.
    for (int i = 0; i < scene.num_spheres; ++i) {
        const float t = intersect_sphere(ray, scene.spheres[i], hit.t);
        if (t < hit.t) {
            hit.t = t;
            hit.sphere = i;
        }
    }
    return hit;
}

// Whether anything blocks the ray before distance t_max. Stops at the first blocker:
// a shadow ray needs any hit, not the closest. Glass blocks too (no caustics).
RT_HD inline bool occluded(const SceneView& scene, const Ray& ray, float t_max) {
    // TODO(lab01): return true when any sphere or triangle lies on the ray before t_max.
    (void)scene;
    (void)ray;
    (void)t_max;
    return false;
}

// Radiance the point light sends to a diffuse surface point through its BRDF:
// rho/pi * I * cos(theta) / d^2 when the segment to the light is clear.
template <class Geometry>
RT_HD inline Vec3 direct_light(const SceneView& scene, const Geometry& geometry, Vec3 origin,
                               Vec3 facing_normal, Vec3 albedo) {
    // TODO(lab01): cast a shadow ray to the light; if it is clear, return
    // albedo/pi * intensity * cos(theta) / distance^2. Until then: no light at all.
    (void)scene;
    (void)geometry;
    (void)origin;
    (void)facing_normal;
    (void)albedo;
    return Vec3(0.0f);
}

// Radiance arriving along a camera ray, estimated by one random path of at most
// max_bounces surface interactions, with next-event estimation at each diffuse one.
// A path ends when it escapes (picking up the background) or its budget is spent.
template <class Geometry, class Rng>
RT_HD inline Vec3 trace_path(const SceneView& scene, const Geometry& geometry, Ray ray,
                             const Rng& rng, int max_bounces) {
    Vec3 radiance(0.0f);
    Vec3 throughput(1.0f);
    // TODO(lab01): the path loop. For each bounce: find the closest hit (escaped rays
    // pick up the background), add next-event estimation at diffuse surfaces, then
    // continue the path (cosine-sampled, mirrored or refracted) with a new ray.
    // Until then: flat colour of the first surface seen, no lighting.
    (void)max_bounces;
    (void)rng;
    const Hit hit = closest_hit(geometry, ray);
    if (!hit.found()) return scene.background;
    radiance = scene.materials[surface_at(scene, ray, hit).material].albedo;
    return radiance;
}

// The estimate of one pixel: the mean of spp paths through uniformly jittered points of the
// pixel (a box filter). Pixel index and sample number key the random numbers.
template <class Geometry>
RT_HD inline Vec3 render_pixel(const SceneView& scene, const Geometry& geometry,
                               const Camera& camera, const RenderSettings& settings, int x, int y) {
    const uint64_t pixel = static_cast<uint64_t>(y) * settings.width + x;
    SampleSum sum;  // in double: a float sum drifts by ~1% past a million samples
    // TODO(lab01): average settings.spp paths, each through a random point of the pixel
    // (SampleStream(settings.seed, pixel, s), dimensions kDimPixelX/kDimPixelY).
    // Until then: one path through the pixel's corner.
    const SampleStream rng(settings.seed, pixel, 0);
    sum.add(trace_path(scene, geometry, camera.ray_through(x, y), rng, settings.bounces));
    return sum.mean(1);
}

// Lab 01's geometry is the scene itself: the brute-force loops above.
RT_HD inline Vec3 direct_light(const SceneView& scene, Vec3 origin, Vec3 facing_normal,
                               Vec3 albedo) {
    return direct_light(scene, scene, origin, facing_normal, albedo);
}

template <class Rng>
RT_HD inline Vec3 trace_path(const SceneView& scene, Ray ray, const Rng& rng, int max_bounces) {
    return trace_path(scene, scene, ray, rng, max_bounces);
}

RT_HD inline Vec3 render_pixel(const SceneView& scene, const Camera& camera,
                               const RenderSettings& settings, int x, int y) {
    return render_pixel(scene, scene, camera, settings, x, y);
}
