// Which kinds of primitive a renderer is compiled for: the twin of material_set.h. The
// closest-hit and shadow loops visit every kind in turn; a scene without triangles still pays
// for the triangle loop's setup (the ray's shear) and, on a GPU, for the registers of every
// test compiled in. A renderer instantiated for the kinds its scene has carries only their
// loops (`if constexpr` in path_tracer.h), with the same arithmetic for every primitive it
// does test, so the same bits.
//
// Each set is a type, chosen once per render by dispatch on geometry_kinds(scene).
#pragma once

#include <scene_view.h>

template <bool kWithSpheres, bool kWithTriangles, bool kWithQuads, bool kWithRects>
struct GeometrySet {
    static constexpr bool kSpheres = kWithSpheres;
    static constexpr bool kTriangles = kWithTriangles;
    static constexpr bool kQuads = kWithQuads;  // planar convex quads (convex_quad.h)
    static constexpr bool kRects = kWithRects;  // axis-aligned rectangles (axis_rect.h)
    static constexpr bool kSheared = kWithTriangles || kWithQuads;  // need the RayShear
};

// What a Hit names (path_tracer.h): nothing, or a primitive of one kind.
enum class PrimitiveKind : int { None, Sphere, Triangle, Quad, Rect };

using AnyGeometry = GeometrySet<true, true, true, true>;     // every scene: the default
using BoxGeometry = GeometrySet<true, false, false, true>;   // spheres and rectangles (Cornell)

// The kinds of primitive a scene holds (has_specular_material's twin).
struct GeometryKinds {
    bool spheres, triangles, quads, rects;

    // Whether a renderer compiled for `Set` renders every primitive of the scene.
    template <class Set>
    RT_HD bool fits() const {
        return (Set::kSpheres || !spheres) && (Set::kTriangles || !triangles) &&
               (Set::kQuads || !quads) && (Set::kRects || !rects);
    }
};

RT_HD inline GeometryKinds geometry_kinds(const SceneView& scene) {
    return {scene.num_spheres > 0, scene.num_triangles > 0, scene.num_quads > 0,
            scene.num_rects > 0};
}
