// What the path tracer's steps read and write (path_steps.h, path_tracer.h): the hit a
// closest-hit query finds, the surface point at it, a path's state between two queries and
// the shadow ray a light sample waits for; and the look-ups the bounce step makes (the
// surface at a hit, the step off a primitive's edges).
#pragma once

#include <geometry_set.h>
#include <scene_view.h>

// The nearest surface a ray meets: which primitive and how far.
// A hit is a kind and an index, not an index per kind: 12 bytes for any number of kinds, and a
// wavefront packs it into 8 (packed_hit.cuh).
struct Hit {
    real t = kRealMax;                         // distance along the ray; kRealMax (real.h)
    PrimitiveKind kind = PrimitiveKind::None;  // when nothing was hit, and then kind is None
    int index = -1;  // the primitive's index in its kind's array (scene_view.h)

    RT_HD bool found() const { return kind != PrimitiveKind::None; }
};

// What shading needs to know about a hit point.
struct SurfacePoint {
    Vec3 position;  // world-space hit point
    Vec3 normal;    // unit geometric normal: outward for spheres, the front side for the others
    real extent;    // the primitive's largest |coordinate|, for offset_ray_origin (ray.h)
    int material;   // index into the material table
};

// The surface of a hit on a kind of Kinds<K, Rest...>: an if-chain over the kinds, the last
// taken without a test (a hit names a kind of the set).
template <class K, class... Rest>
RT_HD inline SurfacePoint surface_of(const SceneView& scene, Vec3 p, const Hit& hit,
                                     Kinds<K, Rest...>) {
    if constexpr (sizeof...(Rest) > 0) {
        if (hit.kind != primitive_kind<K>) return surface_of(scene, p, hit, Kinds<Rest...>{});
    }
    const K& item = scene.of<K>()[hit.index];
    return {p, normal_at(item, p), surface_extent(item), item.material};
}

// The position is ray.at(t), not re-projected onto the primitive (pbrt re-projects sphere hits,
// p = c + r * normalize(p - c)): p - c already rounds to the spacing of floats at |c| + r, the
// error the offset's extent term covers, and measured on sphere floors of radius 1e3..1e6 the
// re-projected points rendered no closer to the closed form. Primitives (geometry_set.h): the
// kinds that can have been hit.
template <class Primitives = AnyGeometry>
RT_HD inline SurfacePoint surface_at(const SceneView& scene, const Ray& ray, const Hit& hit) {
    return surface_of(scene, ray.at(hit.t), hit, Primitives{});
}

// A specular path's step off the edges of the primitive it hit (each kind's step_off_edges:
// zero on a sphere, which has none): an if-chain over the kinds of Kinds<K, Rest...>. Given
// the arriving ray's direction, a cut edge's step takes the side the ray came from
// (triangle.h's step_off_cut_edge); without it, every edge's step is inward.
template <class K, class... Rest, class... Direction>
RT_HD inline Vec3 step_off_edges_of(const SceneView& scene, const Hit& hit, Vec3 p, real margin,
                                    Kinds<K, Rest...>, Direction... direction) {
    if (hit.kind == primitive_kind<K>)
        return step_off_edges(scene.of<K>()[hit.index], p, margin, direction...);
    if constexpr (sizeof...(Rest) > 0) {
        return step_off_edges_of(scene, hit, p, margin, Kinds<Rest...>{}, direction...);
    } else {
        return Vec3(0.0f);
    }
}
template <class Primitives = AnyGeometry>
RT_HD inline Vec3 step_off_hit_edges(const SceneView& scene, const Hit& hit, Vec3 p, real margin) {
    return step_off_edges_of(scene, hit, p, margin, Primitives{});
}
template <class Primitives = AnyGeometry>
RT_HD inline Vec3 step_off_hit_edges(const SceneView& scene, const Hit& hit, Vec3 p, real margin,
                                     Vec3 direction) {
    return step_off_edges_of(scene, hit, p, margin, Primitives{}, direction);
}

// One camera path between two closest-hit queries: all that the bounce step reads and writes.
// A wavefront renderer keeps this per path in its queues, plus the path's pixel and sample
// numbers (they rebuild its SampleStream) and the Hit its intersection kernel found; `alive`
// it need not store, since a path is alive while it is in a queue.
struct PathState {
    Ray ray;          // the ray to trace next (meaningless once the path has ended)
    Vec3 throughput;  // product of the weights of the interactions so far
    Vec3 radiance;    // what the path has gathered so far
    int bounce;       // surface interactions so far: the next one is number `bounce`
    bool alive;       // false once the path has escaped or spent its budget
};

RT_HD inline PathState start_path(const Ray& camera_ray, int max_bounces) {
    return {camera_ray, Vec3(1.0f), Vec3(0.0f), 0, max_bounces > 0};
}

// A light sample waiting for its shadow ray: `radiance` joins the path's radiance unless
// something blocks `ray` before `t_max`. The bounce step fills it in and a shadow query
// decides it: in the path loop below right away, in a wavefront renderer in a kernel of its own.
struct ShadowRay {
    Ray ray;
    real t_max;
    Vec3 radiance;
};
