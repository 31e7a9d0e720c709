// The stages of the wavefront path tracer, one kernel each. Between two closest-hit queries a
// path is the core's PathState, kept in the path pool; the kernels hand paths to each other
// through queues of pool slots (path_queue.cuh). Per bounce:
//
//   find_closest_hits   active queue -> each path's Hit                     (the report's CHIT)
//   shade_hits          active queue -> the core's bounce_step; pushes the paths that go on
//                       to the next active queue and those that asked for a shadow ray to
//                       the shadow queue                                     (PROCESS)
//   trace_shadow_rays   shadow queue -> the light sample's radiance, unless blocked  (AHIT)
//
// and per wave generate_camera_paths (GEN) before the first bounce and accumulate_samples
// (CHECK's job here: the bounce step ends each path, and the finished paths' radiance joins
// its pixel) after the last. Every kernel runs the shared core's functions (start_path,
// closest_hit, bounce_step, occluded, SampleStream, Camera::ray_through) on one path at a
// time: the path's logic is lab 01's, only the loop around it is cut into kernels.
//
// Each kernel is a template on a Config: the pool's layout (AoS here, SoA in lab 07), where
// the scene is read from (scene_pool.cuh), which push the queues use and the material kinds
// compiled into the shading kernel (material_set.h), so that each of those choices is
// measured with everything else the same.
#pragma once

#include <path_tracer.h>

#include "packed_hit.cuh"
#include "path_queue.cuh"
#include "scene_pool.cuh"
#include "wave.cuh"

template <class PoolT, SceneMemory kMemory, bool kAggregated = true, class MaterialsT = AnyMaterial,
          int kMinBlocks = 1>
struct WavefrontConfig {
    using Pool = PoolT;
    using Materials = MaterialsT;  // what shade_hits compiles in: the scene's kinds, or all
    static constexpr SceneMemory kSceneMemory = kMemory;
    static constexpr bool kAggregatedPush = kAggregated;  // push, else push_each_atomic
    // Blocks of kStageThreads each kernel must fit on a multiprocessor (__launch_bounds__):
    // more caps the registers lower, for more warps in flight. 1 leaves the registers to the
    // compiler, which on the H200 was faster than 12 or 16 blocks (handouts/06-cuda-split.md).
    static constexpr int kMinBlocksPerSM = kMinBlocks;
};

// Threads per block of every stage (not tuned: every measurement in the handouts uses 128).
// Each kernel's grid is as many blocks as fit on the GPU at once (wavefront_renderer.cuh),
// and its threads stride over their queue.
constexpr int kStageThreads = 128;

// The most threads one multiprocessor holds, for the architecture being compiled (CUDA's
// occupancy tables): 1024 on Turing, 1536 on consumer Ampere and Ada, 2048 on A100 and Hopper.
// A __launch_bounds__ that asks for more blocks than fit is an error for ptxas, so a Config's
// kMinBlocksPerSM (a measurement made on an H200) is capped at what each target holds.
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ == 750
constexpr int kMaxThreadsPerSM = 1024;
#elif defined(__CUDA_ARCH__) && (__CUDA_ARCH__ == 860 || __CUDA_ARCH__ == 870 || __CUDA_ARCH__ == 890)
constexpr int kMaxThreadsPerSM = 1536;
#else
constexpr int kMaxThreadsPerSM = 2048;
#endif
constexpr int min_blocks_per_sm(int wanted) {
    return wanted * kStageThreads <= kMaxThreadsPerSM ? wanted : kMaxThreadsPerSM / kStageThreads;
}

template <class C>
__device__ inline void enqueue(const PathQueue& queue, int id) {
    if constexpr (C::kAggregatedPush) {
        push(queue, id);
    } else {
        push_each_atomic(queue, id);
    }
}

// GEN: the camera ray of every slot of the wave, as render_pixel makes it (the same jitter
// numbers), and every path onto the first active queue.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    generate_camera_paths(const WavefrontArgs args, const Wave wave, const typename C::Pool pool,
                          const PathQueue active) {
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    for (int slot = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); slot < wave.paths();
         slot += threads) {
        const SampleStream rng = stream_of(args, wave, slot);
        const uint64_t pixel = wave.pixel_of(slot);
        const int x = static_cast<int>(pixel % args.settings.width);
        const int y = static_cast<int>(pixel / args.settings.width);
        const Ray ray = args.camera.ray_through(x + real(rng.at(kDimPixelX)),
                                                y + real(rng.at(kDimPixelY)));
        const PathState path = start_path(ray, args.settings.bounces);
        pool.start_path(slot, path);
        if (path.alive) enqueue<C>(active, slot);
    }
}

// CHIT: the nearest surface on each active path's ray.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    find_closest_hits(const WavefrontArgs args, const typename C::Pool pool, const PathQueue active) {
    extern __shared__ float4 shared_scene[];  // used when the scene is in shared memory
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_queued(active, [&](int id) { pool.store_hit(id, closest_hit(scene, pool.load_ray(id))); });
}

// PROCESS: the core's bounce step at each active path's hit; every path on `active` is about
// to make interaction number `bounce`. A path that goes on is stored and pushed to the next
// bounce's active queue; one whose step asked for a shadow ray, to the shadow queue, with
// the request in its slot. A path that ends simply is not pushed: its radiance stays in its
// slot for accumulate_samples. The step starts from zero radiance and whatever it adds (the
// background, for a path that escapes) joins the slot's radiance afterwards: the same single
// addition the core's loop makes, and no radiance read or written for the other paths.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    shade_hits(const WavefrontArgs args, const Wave wave, const typename C::Pool pool, int bounce,
               const PathQueue active, const PathQueue next, const PathQueue shadows) {
    extern __shared__ float4 shared_scene[];
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_queued(active, [&](int id) {
        PathState path = pool.load_path(id, bounce);
        ShadowRay shadow;
        const bool wants_shadow_ray = bounce_step<typename C::Materials>(
            scene, pool.load_hit(id), stream_of(args, wave, id), args.settings.bounces, path, shadow);
        if (path.radiance.x != 0.0f || path.radiance.y != 0.0f || path.radiance.z != 0.0f) {
            pool.add_radiance(id, path.radiance);
        }
        if (wants_shadow_ray) {
            pool.store_shadow(id, shadow);
            enqueue<C>(shadows, id);
        }
        if (path.alive) {
            pool.store_path(id, path);
            enqueue<C>(next, id);
        }
    });
}

// AHIT: each light sample's shadow ray; any blocker will do (occluded stops at the first).
// Only this kernel writes a queued path's radiance between two shade_hits launches, so the
// addition needs no atomic.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    trace_shadow_rays(const WavefrontArgs args, const typename C::Pool pool, const PathQueue shadows) {
    extern __shared__ float4 shared_scene[];
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_queued(shadows, [&](int id) {
        const ShadowRay shadow = pool.load_shadow(id);
        if (!occluded(scene, shadow.ray, shadow.t_max)) pool.add_radiance(id, shadow.radiance);
    });
}

// CHECK: once every path of the wave has ended, adds each pixel's samples of this wave to
// its sum, in sample order (slot p, p + pixels, p + 2 pixels, ...), so the sum is
// render_pixel's, bit for bit in the double sums; `means`, when given (the band's last wave),
// receives sum.mean(spp). One thread per pixel: no atomics, no order to depend on.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    accumulate_samples(const Wave wave, const typename C::Pool pool, SampleSum* sums, Vec3* means,
                       int spp) {
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    for (int p = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); p < wave.pixels;
         p += threads) {
        SampleSum sum = sums[p];
        for (int s = 0; s < wave.samples; ++s) sum.add(pool.load_radiance(p + s * wave.pixels));
        sums[p] = sum;
        if (means) means[p] = sum.mean(spp);
    }
}
