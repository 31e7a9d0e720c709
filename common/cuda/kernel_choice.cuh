// Which compiled kernel renders a scene: where its pool lives (scene_pool.cuh), which material
// kinds (material_set.h) and which primitive kinds (geometry_set.h) the kernel carries code
// for. A kernel compiled for fewer kinds needs fewer registers and, for primitives, runs only
// the loops the scene has; a renderer compiles a short menu of sets and gives each scene the
// most specific one that holds it.
#pragma once

#include <geometry_set.h>
#include <material_set.h>
#include <scene_pool.cuh>

// Every primitive kind but the axis-aligned rectangle: a scene whose quads are not aligned
// with the axes (and the Cornell box rendered with its walls as convex quads).
using GeneralGeometry = without_kind<AllPrimitives, AxisRect>;

// A kernel's compile-time choices, as one type a renderer's templates take.
template <SceneMemory kSceneMemory, class MaterialKinds, class PrimitiveKinds>
struct KernelChoice {
    static constexpr SceneMemory kMemory = kSceneMemory;
    using Materials = MaterialKinds;
    using Primitives = PrimitiveKinds;
};

template <class T>
struct KindsTag {
    using type = T;
};

// Calls f(KernelChoice<...>{}) for the kernel that renders a scene and returns what f
// returns: the scene in `memory` (Constant or Global), DiffuseOnly unless the scene has a
// mirror or glass, and the first of BoxGeometry, GeneralGeometry and AnyGeometry that holds
// every primitive kind it has. 2 x 2 x 3 kernels are compiled.
template <class F>
auto with_kernel_choice(SceneMemory memory, bool specular, const GeometryKinds& kinds, F&& f) {
    const auto for_primitives = [&](auto primitives) {
        using Primitives = typename decltype(primitives)::type;
        const auto for_materials = [&](auto materials) {
            using Materials = typename decltype(materials)::type;
            return memory == SceneMemory::Constant
                       ? f(KernelChoice<SceneMemory::Constant, Materials, Primitives>{})
                       : f(KernelChoice<SceneMemory::Global, Materials, Primitives>{});
        };
        return specular ? for_materials(KindsTag<AnyMaterial>{})
                        : for_materials(KindsTag<DiffuseOnly>{});
    };
    if (kinds.fits<BoxGeometry>()) return for_primitives(KindsTag<BoxGeometry>{});
    if (kinds.fits<GeneralGeometry>()) return for_primitives(KindsTag<GeneralGeometry>{});
    return for_primitives(KindsTag<AnyGeometry>{});
}
