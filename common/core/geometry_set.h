// Which kinds of primitive a renderer is compiled for: the twin of material_set.h. The
// closest-hit and shadow loops visit every kind in turn; a scene without triangles still pays
// for the triangle loop's setup (the ray's shear) and, on a GPU, for the registers of every
// test compiled in. A renderer instantiated for the kinds its scene has carries only their
// loops (`if constexpr` in path_steps.h), with the same arithmetic for every primitive it
// does test, so the same bits.
//
// A set names its kinds (Kinds<Sphere, AxisRect>, kinds.h), drawn from AllPrimitives
// (primitive_kinds.h); each set is a type, chosen once per render by dispatch on
// geometry_kinds(scene).
#pragma once

#include <primitive_kinds.h>
#include <scene_view.h>

// What a Hit names (path_state.h): nothing, or a primitive of one kind, numbered by its
// position in AllPrimitives from 1 (primitive_kind<Sphere> is 1).
enum class PrimitiveKind : int { None = 0 };

template <class K>
struct PrimitiveKindOf {
    static_assert(has_kind<AllPrimitives, K>, "a primitive kind is one of AllPrimitives");
    static constexpr PrimitiveKind value =
        static_cast<PrimitiveKind>(kind_index<AllPrimitives, K> + 1);
};
template <class K>
constexpr PrimitiveKind primitive_kind = PrimitiveKindOf<K>::value;

using AnyGeometry = AllPrimitives;             // every scene: the default
using BoxGeometry = Kinds<Sphere, AxisRect>;   // spheres and rectangles (Cornell)

// The position in Set of the first kind whose test shears the ray (K::kShearsRay; RayShear,
// triangle.h).
template <class... K>
constexpr int first_shearing_index(Kinds<K...>) {
    const bool shears[] = {K::kShearsRay..., false};
    for (int i = 0; i < static_cast<int>(sizeof...(K)); ++i)
        if (shears[i]) return i;
    return -1;
}
template <class Set>
constexpr int first_shearing = first_shearing_index(Set{});  // -1: none

// Whether the scene has primitives of a kind of Set whose test shears the ray: only then is
// the shear built (a scene of spheres and rectangles pays nothing for it).
template <class Set>
RT_HD inline bool has_sheared_primitives(const SceneView& scene) {
    bool any = false;
    for_each_kind(Set{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (K::kShearsRay) any = any || scene.of<K>().count > 0;
    });
    return any;
}

// Calls visit(KindTag<K>{}) for every kind K of Set, in the list's order but that the kinds
// whose test shears the ray are visited together, at the first of them, as
// visit(KindTag<K>{}, shear) with one RayShear of the ray, built only when the scene has
// primitives of such a kind. The shear is alive only while those kinds are tested: on a GPU
// its registers would otherwise be held through every other kind's loop.
template <class Set, class Visit>
RT_HD RT_FORCE_INLINE void for_each_kind_with_shear(const SceneView& scene, const Ray& ray,
                                                    Visit&& visit) {
    for_each_kind(Set{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (!K::kShearsRay) {
            visit(kind);
        } else if constexpr (kind_index<Set, K> == first_shearing<Set>) {
            if (has_sheared_primitives<Set>(scene)) {
                const RayShear shear(ray.direction);
                for_each_kind(Set{}, [&](auto sheared) {
                    if constexpr (decltype(sheared)::type::kShearsRay) visit(sheared, shear);
                });
            }
        }
    });
}

// The kinds of primitive a scene holds (has_specular_material's twin): one flag per kind of
// AllPrimitives, in its order.
struct GeometryKinds {
    bool present[AllPrimitives::kCount];

    template <class K>
    RT_HD bool has() const {
        return present[kind_index<AllPrimitives, K>];
    }

    // Whether a renderer compiled for `Set` renders every primitive of the scene.
    template <class Set>
    RT_HD bool fits() const {
        bool fits = true;
        for_each_kind(AllPrimitives{}, [&](auto kind) {
            using K = typename decltype(kind)::type;
            fits = fits && (has_kind<Set, K> || !has<K>());
        });
        return fits;
    }
};

// The kinds of a scene that holds exactly Set's kinds (for tests and benchmarks).
template <class Set>
RT_HD GeometryKinds geometry_kinds_of() {
    GeometryKinds kinds{};
    for_each_kind(Set{}, [&](auto kind) {
        kinds.present[kind_index<AllPrimitives, typename decltype(kind)::type>] = true;
    });
    return kinds;
}

RT_HD inline GeometryKinds geometry_kinds(const SceneView& scene) {
    GeometryKinds kinds{};
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        kinds.present[kind_index<AllPrimitives, K>] = scene.of<K>().count > 0;
    });
    return kinds;
}
