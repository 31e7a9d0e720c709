// Lab 03: lab 01's pixel loop, shared among the cores with OpenMP.
//
// Each pixel is still lab 01's render_pixel (through PixelRenderer), and its random numbers
// are a function of (seed, pixel, sample, dimension) only, never of which thread draws them
// or when. Threads share no state but the read-only scene and disjoint rows of the image, so
// the image is lab 01's, bit for bit, for any thread count and any schedule.
//
// Built with -DRT_USE_SIMD (lab03-simd-ref), each pixel uses lab 02's AVX2 geometry instead.
// Built with -DRT_RUNTIME_SCHEDULE (lab03-bench), the loop takes its schedule from the
// OMP_SCHEDULE environment variable, which is how the handout's schedule table is measured.
#include <omp.h>

#include <string>

#include "lab.h"
#include "pixel_renderer.h"
#include "timer.h"

const char* const kLabName = "03-openmp";

// The team size: --threads T, or for T = 0 every core OpenMP may use (the CPUs this process
// may run on, unless OMP_NUM_THREADS says otherwise).
static int thread_count(int requested) {
    // BEGIN SOLUTION
    return requested > 0 ? requested : omp_get_max_threads();
    // SKELETON
    //> // TODO(lab03): return `requested` when it is positive; for 0 ("every core"), ask
    //> // OpenMP how many threads it would use (omp_get_max_threads()).
    //> (void)requested;
    //> return 1;
    // END SOLUTION
}

RenderStats render(const RenderJob& job, Image& image) {
    const PixelRenderer pixel(job);
    const int width = job.settings.width;
    const int height = job.settings.height;
    const int threads = thread_count(job.threads);
    const Timer timer;
    // BEGIN SOLUTION
    // One row at a time to whichever thread is free: schedule(dynamic, 1). Rows differ in
    // cost (the sphere, the shadows and the light's corner make longer paths and more
    // shadow rays), so static blocks finish at different times and the first thread done
    // waits for the last. A row is thousands of paths, milliseconds of work, so handing
    // rows out one by one costs nothing measurable, and one-row chunks leave the least
    // work over at the end. The handout's table measures this against static and guided.
#if defined(RT_RUNTIME_SCHEDULE)
#pragma omp parallel for schedule(runtime) num_threads(threads)
#else
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
#endif
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) image.at(x, y) = pixel(x, y);
        job.progress.rows_done();  // thread-safe
    }
    // SKELETON
    //> // TODO(lab03): share the rows among `threads` threads with an OpenMP parallel loop,
    //> // and choose its schedule by measuring (see the handout). Until then: correct, but
    //> // serial, whatever --threads says.
    //> for (int y = 0; y < height; ++y) {
    //>     for (int x = 0; x < width; ++x) image.at(x, y) = pixel(x, y);
    //>     job.progress.rows_done();
    //> }
    // END SOLUTION
    const double seconds = timer.seconds();
    return {seconds, cpu_model_name() + ", " + std::to_string(threads) +
                         (threads == 1 ? " thread" : " threads")};
}
