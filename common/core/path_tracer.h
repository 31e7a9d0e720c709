// The path tracer every lab shares: the path loop around its steps and the per-pixel
// estimator's lab-01 form. The steps themselves (the primitive loops, the light sample, the
// bounce step, the estimator) are path_steps.h's, the part lab 01's students write; what
// they read and write, path_state.h's.
//
// The path loop is written once for any Geometry: a type for which closest_hit(geometry, ray)
// and occluded(geometry, ray, t_max) exist. Lab 01's geometry is the SceneView itself (the
// brute-force loops of path_steps.h); lab 02 supplies an 8-wide AVX2 one. Likewise any Rng
// with `float at(uint32_t dimension) const` will do; the labs use SampleStream.
#pragma once

#include <path_state.h>
#include <path_steps.h>

// Radiance arriving along a camera ray, estimated by one random path of at most
// max_bounces surface interactions: closest hit, bounce step, and the shadow ray it asks for
// traced at once (its radiance added if nothing blocks it), until the path ends.
// (Its default template arguments are on its declaration, path_steps.h.)
template <class Materials, class Primitives, class Geometry, class Rng>
RT_HD inline Vec3 trace_path(const SceneView& scene, const Geometry& geometry, Ray ray,
                             const Rng& rng, int max_bounces) {
    PathState path = start_path(ray, max_bounces);
    while (path.alive) {
        const Hit hit = closest_hit<Primitives>(geometry, path.ray);
        ShadowRay shadow;
        if (bounce_step<Materials, Primitives>(scene, hit, rng, max_bounces, path, shadow) &&
            !occluded<Primitives>(geometry, shadow.ray, shadow.t_max)) {
            path.radiance += shadow.radiance;
        }
    }
    return path.radiance;
}

// The radiance of one light sample with its shadow ray traced: sample_light, then occluded.
template <class Primitives = AnyGeometry, class Geometry>
RT_HD inline Vec3 direct_light(const SceneView& scene, const Geometry& geometry, Vec3 position,
                               Vec3 origin, Vec3 facing_normal, Vec3 albedo) {
    ShadowRay shadow;
    if (!sample_light(scene, position, origin, facing_normal, albedo, shadow)) return Vec3(0.0f);
    return occluded<Primitives>(geometry, shadow.ray, shadow.t_max) ? Vec3(0.0f) : shadow.radiance;
}

// Lab 01's geometry is the scene itself: the brute-force loops of path_steps.h.
RT_HD inline Vec3 direct_light(const SceneView& scene, Vec3 position, Vec3 origin,
                               Vec3 facing_normal, Vec3 albedo) {
    return direct_light(scene, scene, position, origin, facing_normal, albedo);
}

template <class Materials = AnyMaterial, class Primitives = AnyGeometry, class Rng>
RT_HD inline Vec3 trace_path(const SceneView& scene, Ray ray, const Rng& rng, int max_bounces) {
    return trace_path<Materials, Primitives>(scene, scene, ray, rng, max_bounces);
}

template <class Materials = AnyMaterial, class Primitives = AnyGeometry>
RT_HD inline Vec3 render_pixel(const SceneView& scene, const Camera& camera,
                               const RenderSettings& settings, int x, int y) {
    return render_pixel<Materials, Primitives>(scene, scene, camera, settings, x, y);
}
