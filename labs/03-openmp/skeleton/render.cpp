// Lab 03: your copy, yours to edit. Every place to fill in is marked TODO(lab03).
// Lab 03: lab 01's pixel loop, shared among the cores with OpenMP.
//
// Each pixel is still lab 01's render_pixel (through PixelRenderer), and its random numbers
// are a function of (seed, pixel, sample, dimension) only, never of which thread draws them
// or when. Threads share no state but the read-only scene and disjoint rows of the image, so
// the image is lab 01's, bit for bit, for any thread count and any schedule.
//
// Two other builds of this file (labs/03-openmp/lab.mk):
//   -DRT_RUNTIME_SCHEDULE (lab03-bench): the loop takes its schedule from the OMP_SCHEDULE
//       environment variable, which is how the handout's schedule table is measured.
//   common/simd/ first on the include path, -DRT_USE_SIMD -mavx2 -mfma (lab03-simd-ref): each pixel
//       with lab 02's AVX2 packet tracer (its pixel_renderer.h stands in for the scalar one).
#include <omp.h>

#include <string>

#include "lab.h"
#include "pixel_renderer.h"
#include "timer.h"

#if defined(RT_USE_SIMD)
// This file is then built with AVX2, so it may not run before the CPU is checked:
// simd_entry.cpp (built without AVX2) defines render(), checks, then calls this one.
const char* const kLabName = "03-openmp-simd";
#define render render_avx2
#else
const char* const kLabName = "03-openmp";
#endif

// The team size: --threads T, or for T = 0 every core OpenMP may use (the CPUs this process
// may run on, unless OMP_NUM_THREADS says otherwise).
static int thread_count(int requested) {
    // TODO(lab03): return `requested` when it is positive; for 0 ("every core"), ask
    // OpenMP how many threads it would use (omp_get_max_threads()).
    (void)requested;
    return 1;
}

RenderStats render(const RenderJob& job, Image& image) {
    const PixelRenderer pixel(job);
    const int width = job.settings.width;
    const int height = job.settings.height;
    const int threads = thread_count(job.threads);
    const Timer timer;
    // TODO(lab03): share the rows among `threads` threads with an OpenMP parallel loop,
    // and choose its schedule by measuring (see the handout). Until then: correct, but
    // serial, whatever --threads says.
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) image.at(x, y) = pixel(x, y);
        job.progress.rows_done();
    }
    const double seconds = timer.seconds();
    return {seconds, cpu_model_name() + ", " + std::to_string(threads) +
                         (threads == 1 ? " thread" : " threads")};
}
