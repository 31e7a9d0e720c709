// What lab 05's megakernel is made of besides the loops its students write: a launch's
// arguments, a sample's camera ray and random numbers, how a thread traces its samples
// (PathLoop), the warp's sum of a pixel's partial sums, and what the kernel tests rays
// against. render_kernel.cuh (the students' file) builds the kernel from them.
#pragma once

#include <cstdint>
#include <cstring>

#include <path_tracer.h>

#include <scene_pool.cuh>
#include <slab_geometry.cuh>

// What one launch renders: rows [first_row, first_row + rows) of the image, into `pixels`
// (rows x width, row-major). A large image is rendered as several such bands.
struct KernelArgs {
    SceneLayout layout;         // where the scene's arrays lie in the pool
    const float4* scene_pool;   // the pool in global memory (also the source of the copies)
    Camera camera;              // for the whole image
    RenderSettings settings;    // width, height, spp, bounces, seed
    int first_row;              // the band's first image row
    int rows;                   // the band's height
    Vec3* pixels;               // the band's pixels in device memory
};

// The camera ray and random numbers of sample s of pixel (x, y): what the core's render_pixel
// uses for it.
struct CameraSample {
    SampleStream rng;
    Ray ray;
};

// The stream's key is three 64-bit hashes, about 70 instructions, and the compiler would
// rather compute it again at every bounce than hold its two registers across the path: an
// empty asm that may change it stops that (its result is only known by keeping it).
__device__ inline SampleStream kept_in_registers(SampleStream rng) {
    static_assert(sizeof(SampleStream) == sizeof(unsigned long long), "one 64-bit key");
    unsigned long long key;
    memcpy(&key, &rng, sizeof key);
    asm("" : "+l"(key));
    memcpy(&rng, &key, sizeof key);
    return rng;
}

__device__ inline CameraSample camera_sample(const KernelArgs& args, int x, int y, uint64_t pixel,
                                             int s) {
    const SampleStream rng =
        kept_in_registers(SampleStream(args.settings.seed, pixel, static_cast<uint64_t>(s)));
    return {rng,
            args.camera.ray_through(x + real(rng.at(kDimPixelX)), y + real(rng.at(kDimPixelY)))};
}

// How a thread traces its samples. Every form draws the same numbers and runs the same
// operations on each path; all but Claimed also add a lane's samples in the same order, so
// they give the same image bit for bit; lab05-bench times each (handouts/05-cuda-mega.md,
// "Divergence").
enum class PathLoop {
    WholePaths,  // trace_samples: the core's trace_path, one sample after the other
    Together,    // trace_samples_together: the same, with the warp's lanes kept together
    Regenerate,  // trace_samples_regenerating: by bounces, a new sample as soon as one ends
    Claimed,     // trace_samples_claimed: by bounces, the warp's lanes claiming the pixel's
                 // samples as their paths end
};

// A ray for a lane that traces no path: finite, so that no test takes the slow path of a
// division or square root for it (a NaN direction would, in the rectangles' reciprocals);
// what it meets is never used. As a shadow ray with t_max 0 it is blocked by nothing.
__device__ inline Ray idle_ray() { return {Vec3(0.0f), Vec3(1.0f)}; }

// The two random numbers a bounce step draws (bounce_dimension(bounce, 0) and (bounce, 1)),
// drawn before it is called: the bounce step reads them from here, and any other dimension
// from the path's stream. The claimed loop draws them with the same instructions that draw
// a new sample's pixel jitter.
struct DrawnNumbers {
    SampleStream stream;  // the path's
    uint32_t first;  // bounce_dimension(bounce, 0)
    float u0, u1;  // the numbers of dimensions first and first + 1

    __device__ float at(uint32_t dimension) const {
        return dimension == first ? u0 : dimension == first + 1 ? u1 : stream.at(dimension);
    }
};

// The total of the partial sums of kLanes neighbouring lanes (kLanes a power of two, at most
// a warp), by a butterfly of shuffles: after step k every lane holds the sum of its group of
// 2^k lanes. Every lane of the warp must call it. The order of the additions depends on lane
// numbers only, and a + b == b + a exactly, so all kLanes lanes end with the same bits on
// every run.
template <int kLanes>
__device__ inline SampleSum sum_across_lanes(SampleSum sum) {
    static_assert(kLanes >= 1 && kLanes <= 32 && (kLanes & (kLanes - 1)) == 0,
                  "a pixel's threads must be a power of two within one warp");
#pragma unroll
    for (int offset = kLanes / 2; offset > 0; offset /= 2) {
        sum.r += __shfl_xor_sync(0xffffffffu, sum.r, offset);
        sum.g += __shfl_xor_sync(0xffffffffu, sum.g, offset);
        sum.b += __shfl_xor_sync(0xffffffffu, sum.b, offset);
    }
    return sum;
}

// What the kernel tests rays against: the core's tests with the rectangles as slabs
// (SlabGeometry), or with kSlabRects false the core's own loops over the scene, the
// rectangles' exact test included (what lab05-bench's exact-rects shape measures).
template <bool kSlabRects, SceneMemory kMemory>
__device__ inline auto kernel_geometry(const SceneView& scene, const float4* global_pool,
                                       const float4* shared_pool) {
    if constexpr (kSlabRects) {
        return SlabGeometry{scene, slabs_in<kMemory>(global_pool, shared_pool)};
    } else {
        return scene;
    }
}
