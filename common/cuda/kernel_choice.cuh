// Which compiled kernel renders a scene: where its pool lives (scene_pool.cuh), which material
// kinds (material_set.h) and which primitive kinds (geometry_set.h) the kernel carries code
// for. A kernel compiled for fewer kinds needs fewer registers and, for primitives, runs only
// the loops the scene has; a renderer compiles a short menu of sets and gives each scene the
// most specific one that holds it. Most specific of all is a kernel compiled for the scene's
// counts (small_scene.cuh): lab05-ref gives it every scene it holds (with_small_scene_choice,
// below) and the kinds kernel (with_kernel_choice) every other.
#pragma once

#include <stdexcept>
#include <string>

#include <geometry_set.h>
#include <material_set.h>
#include <scene_pool.cuh>
#include <small_scene.cuh>

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

// ---- the small-scene kernel (small_scene.cuh) --------------------------------------------

// How lab05-ref compiles it, each choice measured with lab05-bench on the Cornell baseline
// (docs/gpu-tuning.md): the hit's surface loaded by the hit's index (one load whose address
// the warp's lanes share or nearly) rather than chosen by selects; at most 56 registers, or
// 64 when built with --use_fast_math. Fast math's approximations let ptxas keep far more
// values live, and held to 56 they spill inside the loop; the fast-math build also passes
// -Xptxas --register-usage-level=3, so that ptxas fits the loop in 64 without spilling.
// nvcc defines no macro for --use_fast_math, so the builds that pass it
// (labs/05-cuda-mega/lab.mk) define RT_LAB05_FAST_MATH beside it.
constexpr bool kSmallSceneBySelects = false;
#ifdef RT_LAB05_FAST_MATH
constexpr int kSmallSceneMaxRegisters = 64;
#else
constexpr int kSmallSceneMaxRegisters = 56;
#endif

// The small-scene kernel for kSpheres spheres and kRects rectangles, as one type a renderer's
// templates take (the scene lives in the kernel's own bank, small_scene.cuh).
template <int kSpheres, int kRects>
struct SmallSceneChoice {
    static constexpr int kSphereCount = kSpheres;
    static constexpr int kRectCount = kRects;
};

// Calls f(SmallSceneChoice<spheres, rects>{}) for a scene that is_small_scene holds (at most
// kSmallSceneMaxSpheres spheres and kSmallSceneMaxRects rectangles) and returns what f returns:
// one kernel per pair of counts, (kSmallSceneMaxSpheres + 1) x (kSmallSceneMaxRects + 1)
// compiled. The search starts at (kSpheres, kRects); counts beyond the limits are the caller's
// error (check is_small_scene first): they get the largest kernel, which would read past the
// scene's numbers, so they are refused here as a logic error.
template <int kSpheres = 0, int kRects = 0, class F>
auto with_small_scene_choice(int spheres, int rects, F&& f) {
    if (spheres == kSpheres && rects == kRects) return f(SmallSceneChoice<kSpheres, kRects>{});
    if constexpr (kRects < kSmallSceneMaxRects) {
        return with_small_scene_choice<kSpheres, kRects + 1>(spheres, rects, f);
    } else if constexpr (kSpheres < kSmallSceneMaxSpheres) {
        return with_small_scene_choice<kSpheres + 1, 0>(spheres, rects, f);
    } else {
        throw std::logic_error("with_small_scene_choice: " + std::to_string(spheres) +
                               " spheres and " + std::to_string(rects) +
                               " rectangles are more than a small-scene kernel holds");
    }
}
