// A wave: the camera paths the wavefront renderer keeps in flight at once, one per slot of
// the path pool. Slot i of a wave is sample (first_sample + i / pixels) of image pixel
// (first_pixel + i % pixels): neighbouring slots are neighbouring pixels at the same sample,
// so the camera rays of a warp start coherent, and a pixel's samples lie `pixels` slots
// apart, which lets the accumulation kernel read them coalesced.
//
// Waves run one after the other, their samples in increasing order, and each path leaves
// its radiance in its own slot; the accumulation kernel adds a pixel's samples in sample
// order into a double sum. So the image does not depend on the order in which the queues
// happen to hold the paths (which the atomics make different on every run): it is the same
// bits for a fixed seed, and the same sum, in the same order, as the core's render_pixel.
#pragma once

#include <cstdint>

#include <camera.h>
#include <rng.h>
#include <scene_view.h>

#include <scene_pool.cuh>

struct Wave {
    int first_pixel;   // image pixel index (y * width + x) of slot 0
    int pixels;        // consecutive image pixels the wave covers
    int first_sample;  // the wave's first sample number
    int samples;       // samples of each of its pixels

    __host__ __device__ int paths() const { return pixels * samples; }
    __device__ uint64_t pixel_of(int slot) const {
        return static_cast<uint64_t>(first_pixel) + static_cast<uint64_t>(slot % pixels);
    }
    __device__ int sample_of(int slot) const { return first_sample + slot / pixels; }
};

// What every stage of the wavefront reads besides the pool and its queues.
struct WavefrontArgs {
    SceneLayout layout;        // where the scene's arrays lie in scene_pool
    const float4* scene_pool;  // the scene in global memory (scene_pool.cuh)
    Camera camera;             // for the whole image
    RenderSettings settings;   // width, height, spp, bounces, seed
};

// The random numbers of the path in `slot`: keyed by (seed, pixel, sample) exactly as the
// CPU labs key them, so with the bounce number (the core's bounce_dimension) each path draws
// the numbers lab 01 draws for it.
__device__ inline SampleStream stream_of(const WavefrontArgs& args, const Wave& wave, int slot) {
    return SampleStream(args.settings.seed, wave.pixel_of(slot),
                        static_cast<uint64_t>(wave.sample_of(slot)));
}
