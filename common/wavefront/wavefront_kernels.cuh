// The stages of the wavefront path tracer, one kernel each. Between two closest-hit queries a
// path is an item on a queue (path_queue.cuh) in the path pool (path_pool.cuh): the kernels
// hand paths to each other by copying them onto the next stage's queue. Per bounce b:
//
//   find_closest_hits   paths(b) -> each path's Hit, beside it in the queue  (the report's CHIT)
//   shade_hits          paths(b) -> the core's bounce_step; pushes the paths that go on onto
//                       paths(b + 1) and the light samples they ask for onto shadows(b)
//                                                                             (PROCESS)
//   trace_shadow_rays   shadows(b) -> the light sample's radiance, unless blocked  (AHIT)
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

#include <path_pool.cuh>
#include <path_queue.cuh>
#include <scene_pool.cuh>
#include <wave.cuh>

template <class LayoutT, SceneMemory kMemory, Reserve kHow = Reserve::kPerBlock,
          class MaterialsT = AnyMaterial, int kMinBlocks = 1, bool kPrefetchNext = false,
          bool kGridPerItem = true, class PrimitivesT = AnyGeometry, bool kTogether = true>
struct WavefrontConfig {
    using Layout = LayoutT;  // AosPathPool (lab 06) or SoaPathPool (lab 07)
    using Pool = PathPool<Layout>;
    using Paths = Queue<typename Layout::Paths>;
    using ShadowRays = Queue<typename Layout::ShadowRays>;
    using Radiance = typename Layout::Radiance;
    using Materials = MaterialsT;  // what shade_hits compiles in: the scene's kinds, or all
    // The primitive kinds the closest-hit, shading and shadow kernels compile in
    // (geometry_set.h): BoxGeometry for a scene of spheres and rectangles, or all of them.
    using Primitives = PrimitivesT;
    static constexpr SceneMemory kSceneMemory = kMemory;
    static constexpr Reserve kReserve = kHow;  // how pushes reserve their places
    // for_each_queued loads each thread's next item ahead (find_closest_hits and
    // trace_shadow_rays): no faster on the H200 (handouts/06-cuda-split.md).
    static constexpr bool kPrefetch = kPrefetchNext;
    // The queue kernels' grids cover the largest queue the wave can make (one thread per
    // place; those past the queue's size return at once), else they fill the GPU once and
    // their threads stride over the queue. One thread per place was 4% faster on the H200:
    // no thread is left with one more item than the others at the end of a launch.
    static constexpr bool kOneItemPerThread = kGridPerItem;
    // A push stores the block's items together where the layout can (lab 06's records, staged
    // in shared memory: path_pool_aos.cuh), else each thread its own.
    static constexpr bool kStoreTogether = kTogether;
    // Blocks of kStageThreads each kernel must fit on a multiprocessor (__launch_bounds__):
    // more caps the registers lower, for more warps in flight. 1 leaves the registers to the
    // compiler, which on the H200 was faster than 12 or 16 blocks (handouts/06-cuda-split.md).
    static constexpr int kMinBlocksPerSM = kMinBlocks;
};

// The most threads one multiprocessor holds, for the architecture being compiled (CUDA's
// occupancy tables): 1024 on Turing, 1536 on consumer Ampere and Ada, 2048 on A100 and Hopper.
// A __launch_bounds__ that asks for more blocks than fit is an error for ptxas, so a Config's
// kMinBlocksPerSM (a measurement made on an H200) is capped at what each target holds.
#if defined(__CUDA_ARCH__) && __CUDA_ARCH__ == 750
constexpr int kMaxThreadsPerSM = 1024;
#elif defined(__CUDA_ARCH__) && \
    (__CUDA_ARCH__ == 860 || __CUDA_ARCH__ == 870 || __CUDA_ARCH__ == 890)
constexpr int kMaxThreadsPerSM = 1536;
#else
constexpr int kMaxThreadsPerSM = 2048;
#endif
constexpr int min_blocks_per_sm(int wanted) {
    return wanted * kStageThreads <= kMaxThreadsPerSM ? wanted : kMaxThreadsPerSM / kStageThreads;
}

// GEN: the camera ray of every slot of the wave, as render_pixel makes it (the same jitter
// numbers), its radiance sum started, and every path onto the first queue.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    generate_camera_paths(const WavefrontArgs args, const Wave wave,
                          const typename C::Radiance radiance, const typename C::Paths paths) {
    for_each_place(wave.paths(), [&](int slot, bool valid) {
        PathState path{};
        if (valid) {
            const SampleStream rng = stream_of(args, wave, slot);
            const uint64_t pixel = wave.pixel_of(slot);
            const int x = static_cast<int>(pixel % args.settings.width);
            const int y = static_cast<int>(pixel / args.settings.width);
            const Ray ray =
                args.camera.ray_through(x + real(rng.at(kDimPixelX)), y + real(rng.at(kDimPixelY)));
            path = start_path(ray, args.settings.bounces);
            radiance.start(slot, path.radiance);
        }
        push<C::kReserve, C::kStoreTogether>(paths, valid && path.alive,
                                             QueuedPath{path.ray, path.throughput, slot});
    });
}

// CHIT: the nearest surface on each queued path's ray, stored beside the path.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    find_closest_hits(const WavefrontArgs args, const typename C::Paths paths) {
    extern __shared__ float4 shared_scene[];  // used when the scene is in shared memory
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_queued<C::kPrefetch>(
        paths, [&](int k) { return paths.items.load_ray(k); },
        [&](int k, const Ray& ray) {
            paths.items.store_hit(k, closest_hit<typename C::Primitives>(scene, ray));
        });
}

// PROCESS: the core's bounce step at each queued path's hit; every path on `paths` is about
// to make interaction number `bounce`. A path that goes on is pushed, with its next ray and
// throughput, onto the next bounce's queue; a light sample its step asked for, onto the
// shadow queue. A path that ends simply is not pushed: its radiance is already in its slot,
// for accumulate_samples. The step starts from zero radiance and whatever it adds (the
// background, for a path that escapes) joins the slot's sum afterwards: the same single
// addition the core's loop makes, and no radiance read or written for the other paths.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    shade_hits(const WavefrontArgs args, const Wave wave, const typename C::Radiance radiance,
               int bounce, const typename C::Paths paths, const typename C::Paths next,
               const typename C::ShadowRays shadows) {
    extern __shared__ float4 shared_scene[];
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_place(*paths.size, [&](int k, bool valid) {
        PathState path{};
        ShadowRay shadow{};
        bool wants_shadow_ray = false;
        int slot = 0;
        if (valid) {
            const QueuedPath queued = paths.items.load(k);
            slot = queued.slot;
            path = {queued.ray, queued.throughput, Vec3(0.0f), bounce, true};
            wants_shadow_ray = bounce_step<typename C::Materials, typename C::Primitives>(
                scene, paths.items.load_hit(k), stream_of(args, wave, slot), args.settings.bounces,
                path, shadow);
            if (path.radiance.x != 0.0f || path.radiance.y != 0.0f || path.radiance.z != 0.0f) {
                radiance.add(slot, path.radiance);
            }
        }
        push<C::kReserve, C::kStoreTogether>(shadows, wants_shadow_ray,
                                             QueuedShadowRay{shadow, slot});
        push<C::kReserve, C::kStoreTogether>(next, valid && path.alive,
                                             QueuedPath{path.ray, path.throughput, slot});
    });
}

// AHIT: each light sample's shadow ray; any blocker will do (occluded stops at the first).
// Only this kernel adds to a slot's radiance between two shade_hits launches, and a path asks
// for one light sample per interaction, so the addition needs no atomic.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    trace_shadow_rays(const WavefrontArgs args, const typename C::Radiance radiance,
                      const typename C::ShadowRays shadows) {
    extern __shared__ float4 shared_scene[];
    const SceneView scene = scene_in<C::kSceneMemory>(args.layout, args.scene_pool, shared_scene);
    for_each_queued<C::kPrefetch>(
        shadows, [&](int k) { return shadows.items.load(k); },
        [&](int, const QueuedShadowRay& queued) {
            const ShadowRay& s = queued.shadow;
            if (!occluded<typename C::Primitives>(scene, s.ray, s.t_max))
                radiance.add(queued.slot, s.radiance);
        });
}

// CHECK: once every path of the wave has ended, adds each pixel's samples of this wave to
// its sum, in sample order (slot p, p + pixels, p + 2 pixels, ...), so the sum is
// render_pixel's, bit for bit in the double sums; `means`, when given (the band's last wave),
// receives sum.mean(spp). One thread per pixel: no atomics, no order to depend on.
template <class C>
__global__ void __launch_bounds__(kStageThreads, min_blocks_per_sm(C::kMinBlocksPerSM))
    accumulate_samples(const Wave wave, const typename C::Radiance radiance, SampleSum* sums,
                       Vec3* means, int spp) {
    const int threads = static_cast<int>(gridDim.x * blockDim.x);
    for (int p = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x); p < wave.pixels;
         p += threads) {
        SampleSum sum = sums[p];
        for (int s = 0; s < wave.samples; ++s) sum.add(radiance.load(p + s * wave.pixels));
        sums[p] = sum;
        if (means) means[p] = sum.mean(spp);
    }
}
