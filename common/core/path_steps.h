// The path tracer's steps, what lab 01's students write: the primitive loops (closest hit,
// shadow test), the light sample and the bounce step (what happens at one hit), and the
// per-pixel estimator. path_tracer.h, the library around them, holds the path loop that
// calls them (trace_path) and includes this file; every renderer of the course calls them
// through it, the CUDA kernels included (a function marked RT_HD runs on the GPU too).
//
// The bounce step is the path's logic, written once for every scalar renderer: the serial
// path loop (and so a CUDA megakernel) calls it between two closest-hit queries, and a
// wavefront renderer's shading kernel calls it on paths it reads from a queue. It neither
// finds the next hit nor traces the shadow ray: it consumes a hit and produces a shadow-ray
// request, because a wavefront renderer runs those queries in kernels of their own.
//
// What they read and write (Hit, SurfacePoint, PathState, ShadowRay, surface_at) is
// path_state.h's.
//!
//! Lab 01 students write the regions between BEGIN/END SOLUTION; the skeleton generator
//! (labkit/skeletons.py) turns this file into labs/01-serial/skeleton/path_steps.h, which
//! stands in for it in ./lab01's build (first on the include path).
#pragma once

#include <cfloat>

#include <camera.h>
#include <geometry_set.h>
#include <material_set.h>
#include <path_state.h>
#include <rng.h>
#include <sample_sum.h>
#include <scene_view.h>

// Closest hit by brute force over every primitive: the scenes of this course are small.
// Primitives (geometry_set.h) is the set of kinds compiled in, each visited with its
// intersect() (primitive_kinds.h) in the order for_each_kind_with_shear gives; each loop keeps
// the nearest hit with a select, no branch out of the loop, so a GPU warp stays converged.
template <class Primitives = AnyGeometry>
RT_HD inline Hit closest_hit(const SceneView& scene, const Ray& ray) {
    Hit hit;
    // BEGIN SOLUTION
    for_each_kind_with_shear<Primitives>(scene, ray, [&](auto kind, const auto&... shear) {
        using K = typename decltype(kind)::type;
        for (int i = 0; i < scene.of<K>().count; ++i) {
            const real t = intersect(ray, shear..., scene.of<K>()[i], hit.t);
            if (t < hit.t) hit = {t, primitive_kind<K>, i};
        }
    });
    // SKELETON
    //> // TODO(lab01): this finds spheres only. Visit every kind of Primitives
    //> // (for_each_kind_with_shear, geometry_set.h: it hands each kind the ray's shear),
    //> // keeping the nearest hit over each kind's array (scene.of<K>()) with the kind's
    //> // intersect(): a hit records its kind and index.
    //> for (int i = 0; has_kind<Primitives, Sphere> && i < scene.of<Sphere>().count; ++i) {
    //>     const real t = intersect_sphere(ray, scene.of<Sphere>()[i], hit.t);
    //>     if (t < hit.t) hit = {t, primitive_kind<Sphere>, i};
    //> }
    // END SOLUTION
    return hit;
}

// Whether anything blocks the ray before distance t_max. Stops at the first blocker:
// a shadow ray needs any hit, not the closest. Glass blocks too (no caustics).
template <class Primitives = AnyGeometry>
RT_HD inline bool occluded(const SceneView& scene, const Ray& ray, real t_max) {
    // BEGIN SOLUTION
    // On a GPU every lane tests every primitive and the answer comes after the loops: an exit
    // at the first blocker would only split the warp (kConvergedTests, rt_hd.h).
    bool blocked = false;
    for_each_kind_with_shear<Primitives>(scene, ray, [&](auto kind, const auto&... shear) {
        using K = typename decltype(kind)::type;
        for (int i = 0; (kConvergedTests || !blocked) && i < scene.of<K>().count; ++i)
            blocked |= occludes(ray, shear..., scene.of<K>()[i], t_max);
    });
    return blocked;
    // SKELETON
    //> // TODO(lab01): return true when any primitive (of every kind of Primitives, as in
    //> // closest_hit, with the kind's occludes()) lies on the ray before t_max.
    //> (void)scene;
    //> (void)ray;
    //> (void)t_max;
    //> return false;
    // END SOLUTION
}

// Next-event estimation at a diffuse point: the point light's radiance through the BRDF,
// rho/pi * I * cos(theta) / d^2, and the shadow ray that decides it. false when the light lies
// behind the surface (no shadow ray needed).
// Distance and cosine are measured from the surface point itself: from the offset origin they
// would change with the offset, which grows with |position|, so moving a whole scene away from
// the world origin would brighten it (+39% for the sphere interior moved 1e4 radii). Only the
// shadow ray starts at the offset origin, parallel to the surface point's direction to the
// light, and it ends where it passes the light: t_max = d - (origin - position).wi, the
// distance minus how far the offset moved along the ray.
RT_HD inline bool sample_light(const SceneView& scene, Vec3 position, Vec3 origin,
                               Vec3 facing_normal, Vec3 albedo, ShadowRay& shadow) {
    // BEGIN SOLUTION
    // Every test is written so that NaN fails it. A light placed on a surface is met by hit
    // points that land on it to the last bit (distance 0: no direction, 0/0), or lie off it
    // by the rounding of their own coordinates only, which then sets the direction to it (a
    // light in a floor's plane lit the floor 1e13 times too bright, where the double build
    // sees ~0). So a light nearer than 2 ulps of the point's largest coordinate, which `real`
    // cannot tell from the point, gives no sample.
    const Vec3 to_light = scene.light.position - position;
    const real distance2 = length_squared(to_light);
    const real resolved = real(2) * kRealEpsilon * max_component(abs(position));
    const real distance = sqrt_real(distance2);
    const Vec3 wi = to_light * (real(1) / distance);
    const real cos_theta = dot(facing_normal, wi);
    // Light behind the surface, not resolved from it, or a falloff cos/(pi d^2) past the range.
    // One branch: & rather than || (each ordered comparison is false for NaN).
    const bool in_front =
        (cos_theta > 0.0f) & (distance > resolved) & (cos_theta < kRealMax * (kPi * distance2));
    if (!in_front) return false;
    shadow.ray = {origin, wi};
    shadow.t_max = distance - dot(origin - position, wi);
    // The light's term saturates at the type's largest value: an intensity near it times a
    // falloff above 1 overflows to inf, which a zero channel of the path's throughput turns
    // into NaN (0 * inf). albedo * intensity is finite (albedo <= 1) and the falloff is finite
    // (tested above), so the product is a number or +inf, never NaN; the throughput it meets
    // next is at most 1. Below the largest value the bits are those of the plain product.
    const Vec3 radiance = albedo * scene.light.intensity * (cos_theta / (kPi * distance2));
    shadow.radiance = {min_float(radiance.x, kRealMax), min_float(radiance.y, kRealMax),
                       min_float(radiance.z, kRealMax)};
    return true;
    // SKELETON
    //> // TODO(lab01): the light sample. From `position`: the direction wi and distance d to
    //> // the light, cos(theta) with the normal; when cos(theta) > 0, a shadow ray from
    //> // `origin` along wi ending where it passes the light, and the radiance
    //> // albedo/pi * intensity * cos(theta) / d^2. Until then: no light at all.
    //> (void)scene;
    //> (void)position;
    //> (void)origin;
    //> (void)facing_normal;
    //> (void)albedo;
    //> (void)shadow;
    //> return false;
    // END SOLUTION
}

// g++ calls a function as big as the bounce step out of line, and the path state then lives in
// memory: +9% instructions per path on the Cornell box (callgrind). Inlined into the path
// loop, the step costs 1% over the loop body it replaced (RT_FORCE_INLINE, rt_hd.h).

// What happens at one hit of the path: an escaped path picks up the background and ends; at a
// surface, next-event estimation at diffuse ones (the shadow-ray request, weighted by the
// throughput: returns true when it made one), then the next ray (cosine-sampled, mirrored, or
// reflected or refracted by Fresnel) with its weight, unless the budget of max_bounces
// interactions is spent. Reads random numbers by the path's bounce number only
// (bounce_dimension), so every renderer that calls it draws the same ones. Materials
// (material_set.h) is the set of material kinds compiled in: a renderer that knows its scene
// has no mirror or glass asks for DiffuseOnly and carries no code for them; Primitives
// (geometry_set.h), the primitive kinds, likewise.
template <class Materials = AnyMaterial, class Primitives = AnyGeometry, class Rng>
RT_HD RT_FORCE_INLINE bool bounce_step(const SceneView& scene, const Hit& hit, const Rng& rng,
                                       int max_bounces, PathState& path, ShadowRay& shadow) {
    // BEGIN SOLUTION
    if (!hit.found()) {
        path.radiance += path.throughput * scene.background;
        path.alive = false;
        return false;
    }
    const SurfacePoint surface = surface_at<Primitives>(scene, path.ray, hit);
    const Material& material = scene.materials[surface.material];
    const Vec3 incoming = path.ray.direction;
    const bool entering = dot(incoming, surface.normal) < 0.0f;
    const Vec3 facing = entering ? surface.normal : -surface.normal;  // toward the ray
    const Vec3 above = offset_ray_origin(surface.position, facing, hit.t, surface.extent);
    const int bounce = path.bounce++;
    path.alive = path.bounce < max_bounces;

    if (!has_specular<Materials> || material.type == material_type<Diffuse>) {
        const bool lit = scene.has_light && sample_light(scene, surface.position, above, facing,
                                                         material.albedo, shadow);
        if (lit) shadow.radiance = path.throughput * shadow.radiance;
        if (path.alive) {
            path.throughput *= material.albedo;
            path.ray = {above, sample_cosine_hemisphere(facing, rng.at(bounce_dimension(bounce, 0)),
                                                        rng.at(bounce_dimension(bounce, 1)))};
        }
        return lit;
    }
    if constexpr (has_specular<Materials>) {
        if (!path.alive) return false;
        // A specular path may bounce 64 times inside a closed mirror or glass room, and must
        // stay inside: its origin also steps off any edge of the primitive it hit (off a cut
        // edge, to the side the path came from).
        const Vec3 off_edges = step_off_hit_edges<Primitives>(
            scene, hit, surface.position, ray_offset(surface.position, hit.t, surface.extent),
            incoming);
        scatter_of(
            material,
            {incoming, facing, entering, above, off_edges, surface.position, hit.t, surface.extent},
            rng, bounce, path.throughput, path.ray, without_kind<Materials, Diffuse>{});
    }
    return false;
    // SKELETON
    //> // TODO(lab01): the bounce step. Escaped paths pick up the background and end; at a
    //> // surface, request next-event estimation at diffuse ones (sample_light, weighted by
    //> // the throughput), then continue the path with a new ray and weight (cosine-sampled
    //> // at diffuse ones; at the others, scatter_of calls their kind's hook, material.h),
    //> // unless this was interaction number max_bounces.
    //> // Until then: flat colour of the first surface seen, no lighting.
    //> (void)rng;
    //> (void)max_bounces;
    //> (void)shadow;
    //> path.alive = false;
    //> path.radiance = hit.found() ? scene.materials[surface_at(scene, path.ray, hit).material].albedo
    //>                             : scene.background;
    //> return false;
    // END SOLUTION
}

// The path loop (path_tracer.h, defined there after the steps it calls): the radiance along
// one camera ray, one random path.
template <class Materials = AnyMaterial, class Primitives = AnyGeometry, class Geometry, class Rng>
RT_HD inline Vec3 trace_path(const SceneView& scene, const Geometry& geometry, Ray ray,
                             const Rng& rng, int max_bounces);

// The estimate of one pixel: the mean of spp paths through uniformly jittered points of the
// pixel (a box filter). Pixel index and sample number key the random numbers. Materials: the
// material kinds compiled in (material_set.h), Primitives the primitive kinds (geometry_set.h),
// both passed on to trace_path.
template <class Materials = AnyMaterial, class Primitives = AnyGeometry, class Geometry>
RT_HD inline Vec3 render_pixel(const SceneView& scene, const Geometry& geometry,
                               const Camera& camera, const RenderSettings& settings, int x, int y) {
    const uint64_t pixel = static_cast<uint64_t>(y) * settings.width + x;
    SampleSum sum;  // in double: a float sum drifts by ~1% past a million samples
    // BEGIN SOLUTION
    for (int s = 0; s < settings.spp; ++s) {
        const SampleStream rng(settings.seed, pixel, s);
        // real(...): the double build places the jitter in double (the random number is float).
        const Ray ray =
            camera.ray_through(x + real(rng.at(kDimPixelX)), y + real(rng.at(kDimPixelY)));
        sum.add(trace_path<Materials, Primitives>(scene, geometry, ray, rng, settings.bounces));
    }
    return sum.mean(settings.spp);
    // SKELETON
    //> // TODO(lab01): average settings.spp paths, each through a random point of the pixel
    //> // (SampleStream(settings.seed, pixel, s), dimensions kDimPixelX/kDimPixelY).
    //> // Until then: one path through the pixel's corner.
    //> const SampleStream rng(settings.seed, pixel, 0);
    //> sum.add(trace_path<Materials, Primitives>(scene, geometry, camera.ray_through(x, y), rng,
    //>                                           settings.bounces));
    //> return sum.mean(1);
    // END SOLUTION
}
