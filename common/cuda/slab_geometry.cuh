// The megakernel's geometry: the core's path loop (path_tracer.h) takes any Geometry for which
// closest_hit and occluded exist, as lab 02's SIMD geometry does. This one tests the
// rectangles as slabs (rect_slabs.cuh) and every other kind with the core's own test, in the
// core's order of kinds, keeping the nearer hit with the same strict comparison: the same
// primitive is found, at a distance that may differ in its last bit for a rectangle.
//
// Every test runs on every lane and ends in a select (no early exit), so a warp runs the
// loops together whatever its lanes' rays.
#pragma once

#include <type_traits>

#include <path_tracer.h>

#include <rect_slabs.cuh>

struct SlabGeometry {
    SceneView scene;        // every kind's array, read by the core's tests
    const RectSlab* slabs;  // one per scene.of<AxisRect>() item, in the same order
};

template <class Primitives = AnyGeometry>
__device__ inline Hit closest_hit(const SlabGeometry& geometry, const Ray& ray) {
    Hit hit;
    for_each_kind_with_shear<Primitives>(geometry.scene, ray, [&](auto kind, const auto&... shear) {
        using K = typename decltype(kind)::type;
        const KindSpan<K> items = geometry.scene.of<K>();
        if constexpr (std::is_same_v<K, AxisRect>) {
            const SlabRay slab_ray(ray);
            for_each_slab(geometry.slabs, items.count, [&](int i, const RectSlab& slab) {
                const SlabSpan span = slab_span(slab_ray, slab);
                if (slab_hit(span, hit.t)) hit = {span.entry, primitive_kind<AxisRect>, i};
            });
        } else {
            // Not unrolled: the compiler would copy the test four times for a count it
            // cannot know, a larger kernel that measured slower (one sphere in the box).
#pragma unroll 1
            for (int i = 0; i < items.count; ++i) {
                const real t = intersect(ray, shear..., items[i], hit.t);
                if (t < hit.t) hit = {t, primitive_kind<K>, i};
            }
        }
    });
    return hit;
}

template <class Primitives = AnyGeometry>
__device__ inline bool occluded(const SlabGeometry& geometry, const Ray& ray, real t_max) {
    bool blocked = false;
    for_each_kind_with_shear<Primitives>(geometry.scene, ray, [&](auto kind, const auto&... shear) {
        using K = typename decltype(kind)::type;
        const KindSpan<K> items = geometry.scene.of<K>();
        if constexpr (std::is_same_v<K, AxisRect>) {
            const SlabRay slab_ray(ray);
            for_each_slab(geometry.slabs, items.count, [&](int, const RectSlab& slab) {
                blocked |= slab_hit(slab_span(slab_ray, slab), t_max);
            });
        } else {
            // Not unrolled: the compiler would copy the test four times for a count it
            // cannot know, a larger kernel that measured slower (one sphere in the box).
#pragma unroll 1
            for (int i = 0; i < items.count; ++i)
                blocked |= occludes(ray, shear..., items[i], t_max);
        }
    });
    return blocked;
}
