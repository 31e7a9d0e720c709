// The megakernel's sample loops and the kernel itself: every thread traces camera paths,
// first ray to last bounce, with the shared core (trace_path, or the bounce_step it loops
// over), so the GPU image is lab 01's estimator with lab 01's random numbers. The threads of
// one pixel split its samples between them and add their partial sums in a fixed order, so
// the image is reproducible bit for bit. The primitive tests are the core's but for the
// rectangles', which are slabs (slab_geometry.cuh). What the loops are built from is in
// megakernel_parts.cuh; megakernel.cuh is what the renderers include.
//!
//! Lab 05's students write the regions between BEGIN/END SOLUTION; labkit/skeletons.py turns
//! this file into labs/05-cuda-mega/skeleton/render_kernel.cuh, which stands in for it in
//! the lab's own build (it comes first on the include path).
#pragma once

#include <megakernel_parts.cuh>

// One thread's samples of pixel (x, y): s = first, first + stride, ... below spp, one after
// the other, each path traced to its end by the core's trace_path. A warp's lanes wait for
// each other at every sample (a lane whose path escapes after one bounce idles while
// another's bounces on), but they stay together: every lane starts its next sample at the
// same time, and inside a path they run the same primitive loops. Materials and Primitives:
// the material and primitive kinds compiled in (material_set.h, geometry_set.h), passed on
// to the core; `geometry` is what the core's path loop tests rays against
// (slab_geometry.cuh).
template <class Materials, class Primitives, class Geometry>
__device__ inline SampleSum trace_samples(const SceneView& scene, const Geometry& geometry,
                                          const KernelArgs& args, int x, int y, uint64_t pixel,
                                          int first, int stride) {
    SampleSum sum;  // in double, as render_pixel's
    // BEGIN SOLUTION
    for (int s = first; s < args.settings.spp; s += stride) {
        const CameraSample c = camera_sample(args, x, y, pixel, s);
        sum.add(trace_path<Materials, Primitives>(scene, geometry, c.ray, c.rng,
                                                  args.settings.bounces));
    }
    // SKELETON
    //> // TODO(lab05): trace samples first, first + stride, ... below args.settings.spp with
    //> // camera_sample and trace_path<Materials, Primitives>(scene, geometry, ...), adding
    //> // each path's radiance to sum.
    //> (void)scene;
    //> (void)geometry;
    //> (void)x;
    //> (void)y;
    //> (void)pixel;
    //> (void)first;
    //> (void)stride;
    // END SOLUTION
    return sum;
}

// trace_samples with the warp's lanes kept together. In trace_path's `while (path.alive)`
// a lane whose path has ended leaves the loop and waits, and the warp runs every later
// bounce split. Here a lane whose path has ended stays in the loop and traces idle_ray()
// (its hit unused) until every lane's path has ended, so the warp runs each bounce's
// primitive loops whole and only the bounce step, branchy by nature, runs on the live lanes
// alone. Keeping count of which lanes still run is not free: handouts/05-cuda-mega.md weighs
// the loops.
template <class Materials, class Primitives, class Geometry>
__device__ inline SampleSum trace_samples_together(const SceneView& scene, const Geometry& geometry,
                                                   const KernelArgs& args, int x, int y,
                                                   uint64_t pixel, int first, int stride) {
    SampleSum sum;
    // BEGIN SOLUTION
    const int spp = args.settings.spp, bounces = args.settings.bounces;
    // The lanes' sample counts differ by at most one: a lane past its last sample traces
    // nothing while the others finish theirs.
    for (int s = first; any_lane(s < spp); s += stride) {
        const bool sampled = s < spp;
        const CameraSample c = camera_sample(args, x, y, pixel, sampled ? s : first);
        PathState path = start_path(c.ray, sampled ? bounces : 0);
        if (!path.alive) path.ray = idle_ray();
        while (any_lane(path.alive)) {
            const Hit hit = closest_hit<Primitives>(geometry, path.ray);
            ShadowRay shadow{idle_ray(), 0.0f, Vec3(0.0f)};
            bool lit = false;
            if (path.alive) {
                lit = bounce_step<Materials, Primitives>(scene, hit, c.rng, bounces, path, shadow);
                if (!path.alive) path.ray = idle_ray();
            }
            if (!occluded<Primitives>(geometry, shadow.ray, shadow.t_max) && lit)
                path.radiance += shadow.radiance;
        }
        if (sampled) sum.add(path.radiance);
    }
    // SKELETON
    //> // TODO(lab05, optional, once trace_samples works): the same samples with the warp's
    //> // lanes kept together: a lane whose path has ended stays in the bounce loop, tracing
    //> // idle_ray(), until every lane's has (any_lane). Until then: trace_samples.
    //> sum = trace_samples<Materials, Primitives>(scene, geometry, args, x, y, pixel, first, stride);
    // END SOLUTION
    return sum;
}

// The same samples, the same paths, the same sum, but by bounces: each iteration of the loop
// is one bounce of the lane's current path (the core's closest_hit, bounce_step and shadow
// query, as in trace_path's loop), and a lane whose path has ended starts its next sample in
// the same iteration ("path regeneration"). Each lane still traces its own share of the
// samples (first, first + stride, ...), so a warp runs until the lane with the most bounces
// in its share is done. The image is bit for bit trace_samples' (the same operations on each
// path, the samples added in the same order).
template <class Materials, class Primitives, class Geometry>
__device__ inline SampleSum trace_samples_regenerating(const SceneView& scene,
                                                       const Geometry& geometry,
                                                       const KernelArgs& args, int x, int y,
                                                       uint64_t pixel, int first, int stride) {
    SampleSum sum;
    // BEGIN SOLUTION
    const int spp = args.settings.spp, bounces = args.settings.bounces;
    int s = first;
    if (s >= spp) return sum;
    CameraSample c = camera_sample(args, x, y, pixel, s);
    PathState path = start_path(c.ray, bounces);
    for (;;) {
        if (path.alive) {
            const Hit hit = closest_hit<Primitives>(geometry, path.ray);
            ShadowRay shadow;
            if (bounce_step<Materials, Primitives>(scene, hit, c.rng, bounces, path, shadow) &&
                !occluded<Primitives>(geometry, shadow.ray, shadow.t_max)) {
                path.radiance += shadow.radiance;
            }
        }
        if (!path.alive) {  // this sample is done: add it, start the next one
            sum.add(path.radiance);
            s += stride;
            if (s >= spp) break;
            c = camera_sample(args, x, y, pixel, s);
            path = start_path(c.ray, bounces);
        }
    }
    // SKELETON
    //> // TODO(lab05, optional, once trace_samples works): the same samples, but one bounce
    //> // per loop iteration (closest_hit<Primitives>(geometry, ...), bounce_step<Materials,
    //> // Primitives>, occluded<Primitives>(geometry, ...), as trace_path's loop does),
    //> // starting the lane's next sample as soon as its path ends. Until then: trace_samples.
    //> sum = trace_samples<Materials, Primitives>(scene, geometry, args, x, y, pixel, first, stride);
    // END SOLUTION
    return sum;
}

// A warp's 32 lanes share one pixel's samples by claiming them: each lane starts with sample
// number `first` (its lane), and whenever paths end, the lanes whose path ends take the next
// samples nobody has claimed, in lane order (a vote, __ballot_sync, says which lanes claim;
// each counts the claimants below it). One iteration is one bounce of every lane's path, and
// every lane runs the whole iteration: the closest hit, the bounce step, a shadow query (of
// idle_ray() when the bounce step asked for none), and the next ray. So the lanes stay busy
// until the pixel has no sample left: a pixel costs its bounces' total over 32, not its
// longest paths'. What would split the warp is made one code for all lanes: a lane whose
// path ends at this hit (it escapes, or this is its last bounce: the bounce step's own
// rule) claims its next sample before the bounce step, and draws that sample's pixel jitter
// where the others draw their bounce's two numbers, by the same instructions (DrawnNumbers).
// Which lane traces which sample depends on the paths' lengths alone, so the image is the
// same bit for bit on every run; each lane adds its samples in the order it claimed them.
template <class Materials, class Primitives, class Geometry>
__device__ inline SampleSum trace_samples_claimed(const SceneView& scene, const Geometry& geometry,
                                                  const KernelArgs& args, int x, int y,
                                                  uint64_t pixel, int first, int stride) {
    SampleSum sum;
    // BEGIN SOLUTION
    const int spp = args.settings.spp, bounces = args.settings.bounces;
    const unsigned lanes_below = (1u << first) - 1u;  // first is the lane: stride is 32
    int unclaimed = stride;  // the pixel's first sample no lane has claimed yet
    bool sampling = first < spp;
    CameraSample c = camera_sample(args, x, y, pixel, sampling ? first : 0);
    PathState path = start_path(sampling ? c.ray : idle_ray(), sampling ? bounces : 0);
    while (__any_sync(0xffffffffu, sampling)) {
        const Hit hit = closest_hit<Primitives>(geometry, path.ray);
        // Whether the path ends at this hit, as the bounce step decides it; a path that ended
        // otherwise (no live path, but a sample held) ends here too.
        const bool ending = sampling && (!path.alive || !hit.found() || path.bounce + 1 >= bounces);
        const unsigned claimants = __ballot_sync(0xffffffffu, ending);
        const int next = unclaimed + __popc(claimants & lanes_below);
        unclaimed += __popc(claimants);
        const SampleStream stream =
            ending ? kept_in_registers(
                         SampleStream(args.settings.seed, pixel, static_cast<uint64_t>(next)))
                   : c.rng;
        const uint32_t drawn = ending ? kDimPixelX : bounce_dimension(path.bounce, 0);
        const DrawnNumbers numbers{c.rng, bounce_dimension(path.bounce, 0), stream.at(drawn),
                                   stream.at(drawn + 1)};
        ShadowRay shadow{idle_ray(), 0.0f, Vec3(0.0f)};
        bool lit = false;
        if (path.alive)
            lit = bounce_step<Materials, Primitives>(scene, hit, numbers, bounces, path, shadow);
        if (!occluded<Primitives>(geometry, shadow.ray, shadow.t_max) && lit)
            path.radiance += shadow.radiance;
        if (ending) {
            sum.add(path.radiance);
            sampling = next < spp;
            c.rng = stream;
            const Ray ray = args.camera.ray_through(x + real(numbers.u0), y + real(numbers.u1));
            path = start_path(sampling ? ray : idle_ray(), sampling ? bounces : 0);
        }
    }
    // SKELETON
    //> // TODO(lab05, optional, once trace_samples works): one pixel per warp, one bounce per
    //> // loop iteration on every lane; a lane whose path ends claims the pixel's next
    //> // unclaimed sample (__ballot_sync of the lanes that claim, __popc of those below it).
    //> // Until then: trace_samples.
    //> sum = trace_samples<Materials, Primitives>(scene, geometry, args, x, y, pixel, first, stride);
    // END SOLUTION
    return sum;
}

// kThreadsPerPixel threads per pixel, neighbours in one warp; thread k of a pixel traces its
// samples k, k + kThreadsPerPixel, k + 2 kThreadsPerPixel, ... (the counts differ by at most
// one), or with PathLoop::Claimed the samples it claims, in the form kLoop says (PathLoop).
// kMemory: where the scene is read from (scene_pool.cuh). __launch_bounds__ tells the
// compiler the block size; kMaxRegisters caps the registers per thread (255, the hardware's
// most, caps nothing), so that more threads fit on a multiprocessor, at the price of spills.
// Materials and Primitives: the material and primitive kinds the scene uses (material_set.h,
// geometry_set.h); a kernel for DiffuseOnly carries no mirror or glass code, one for
// BoxGeometry no triangle or quad test. kSlabRects: kernel_geometry.
template <int kThreadsPerPixel, SceneMemory kMemory, int kBlockThreads,
          PathLoop kLoop = PathLoop::WholePaths, int kMaxRegisters = 255,
          class Materials = AnyMaterial, class Primitives = AnyGeometry, bool kSlabRects = true>
__global__ void __launch_bounds__(kBlockThreads) __maxnreg__(kMaxRegisters)
    render_kernel(const KernelArgs args) {
    extern __shared__ float4 shared_pool[];  // used only when kMemory is Shared
    const SceneView scene = scene_in<kMemory>(args.layout, args.scene_pool, shared_pool);
    const auto geometry = kernel_geometry<kSlabRects, kMemory>(scene, args.scene_pool, shared_pool);
    const int width = args.settings.width;
    // BEGIN SOLUTION
    const long long thread = static_cast<long long>(blockIdx.x) * kBlockThreads + threadIdx.x;
    const long long band_pixel = thread / kThreadsPerPixel;
    const int first_sample = static_cast<int>(thread % kThreadsPerPixel);
    // Threads past the band's last pixel (the last block's tail) add nothing but still take
    // part in the shuffles, which need every lane of the warp.
    const bool inside = band_pixel < static_cast<long long>(args.rows) * width;
    const int x = static_cast<int>(band_pixel % width);
    const int y = args.first_row + static_cast<int>(band_pixel / width);
    const uint64_t pixel = static_cast<uint64_t>(y) * width + x;  // the RNG's pixel key

    SampleSum sum;
    if (inside) {
        if constexpr (kLoop == PathLoop::Claimed) {
            static_assert(kThreadsPerPixel == 32, "claimed samples: a warp per pixel");
            sum = trace_samples_claimed<Materials, Primitives>(scene, geometry, args, x, y, pixel,
                                                               first_sample, kThreadsPerPixel);
        } else if constexpr (kLoop == PathLoop::Together) {
            sum = trace_samples_together<Materials, Primitives>(scene, geometry, args, x, y, pixel,
                                                                first_sample, kThreadsPerPixel);
        } else if constexpr (kLoop == PathLoop::Regenerate) {
            sum = trace_samples_regenerating<Materials, Primitives>(
                scene, geometry, args, x, y, pixel, first_sample, kThreadsPerPixel);
        } else {
            sum = trace_samples<Materials, Primitives>(scene, geometry, args, x, y, pixel,
                                                       first_sample, kThreadsPerPixel);
        }
    }
    sum = sum_across_lanes<kThreadsPerPixel>(sum);
    if (inside && first_sample == 0) args.pixels[band_pixel] = sum.mean(args.settings.spp);
    // SKELETON
    //> // TODO(lab05): the kernel. Give each thread its share of the band's work: from
    //> // blockIdx.x, kBlockThreads and threadIdx.x, its pixel (x, y) and the first of that
    //> // pixel's samples it traces (kThreadsPerPixel threads per pixel,
    //> // trace_samples<Materials, Primitives>); skip what lies past the band's last pixel; combine the
    //> // pixel's partial sums (sum_across_lanes) and store sum.mean(spp) once per pixel in
    //> // args.pixels (band-relative index). Until then: one thread per image row walks the
    //> // row's pixels, one path each.
    //> const int row = static_cast<int>(blockIdx.x * kBlockThreads + threadIdx.x);
    //> if (row >= args.rows) return;
    //> const int y = args.first_row + row;
    //> for (int x = 0; x < width; ++x) {
    //>     const uint64_t pixel = static_cast<uint64_t>(y) * width + x;
    //>     const CameraSample c = camera_sample(args, x, y, pixel, 0);
    //>     args.pixels[static_cast<long long>(row) * width + x] =
    //>         trace_path(scene, geometry, c.ray, c.rng, args.settings.bounces);
    //> }
    // END SOLUTION
}
