// Lab 03's classic mistake, built on purpose: one stateful random-number generator shared by
// every thread, as in the course report's OpenMP version. Not a solution; do not copy it.
// The handout measures it against the reference. Two builds of this one file:
//
//   lab03-shared-rng       every draw inside `#pragma omp critical`. No data race, but the
//                          threads queue for one lock (and one cache line) on every draw, and
//                          which numbers a pixel gets depends on the order the threads
//                          happened to arrive in, so the image changes from run to run.
//   lab03-shared-rng-race  (-DRT_SHARED_RNG_RACE) no lock at all: a data race, which is
//                          undefined behaviour. Draws are lost or repeated between threads,
//                          the generator's cache line bounces between cores, and the image
//                          changes from run to run.
//
// The fix is lab 01's counter-based SampleStream (common/core/rng.h): no state, so nothing to
// share. See solution/render.cpp.
#include <omp.h>

#include <cstdint>
#include <string>

#include "lab.h"
#include "path_tracer.h"
#include "timer.h"

#if defined(RT_SHARED_RNG_RACE)
const char* const kLabName = "03-openmp-shared-rng-race";
#else
const char* const kLabName = "03-openmp-shared-rng";
#endif

// A 64-bit linear congruential generator (Knuth's MMIX constants) whose state all threads
// share. It fits trace_path's Rng interface, `float at(uint32_t dimension) const`, only by
// ignoring the dimension: a stateful generator cannot say "dimension d of sample s", only
// "the next number", so what a pixel gets depends on everything drawn before it.
class SharedLcg {
public:
    explicit SharedLcg(uint64_t seed) : state_(mix64(seed)) {}

    float at(uint32_t /*dimension*/) const {
#if defined(RT_SHARED_RNG_RACE)
        return next();  // unsynchronised read-modify-write of state_: the data race
#else
        float u;
#pragma omp critical(shared_rng)
        u = next();  // one thread at a time, on every one of ~10 draws per path
        return u;
#endif
    }

private:
    float next() const {
        state_ = state_ * 6364136223846793005ull + 1442695040888963407ull;
        return unit_float(state_);  // the 24 high bits, the LCG's best
    }

    mutable uint64_t state_;  // mutable: drawing changes it, which is the whole problem
};

RenderStats render(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    const int threads = job.threads > 0 ? job.threads : omp_get_max_threads();
    const SharedLcg rng(settings.seed);  // one generator for the whole image: the mistake
    const Timer timer;
    // Everything else is the reference: rows, dynamic schedule, lab 01's pixel estimator.
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            SampleSum sum;
            for (int s = 0; s < settings.spp; ++s) {
                const Ray ray =
                    job.camera.ray_through(x + rng.at(kDimPixelX), y + rng.at(kDimPixelY));
                sum.add(trace_path(scene, scene, ray, rng, settings.bounces));
            }
            image.at(x, y) = sum.mean(settings.spp);
        }
        job.progress.rows_done();
    }
    const double seconds = timer.seconds();
    return {seconds, cpu_model_name() + ", " + std::to_string(threads) +
                         (threads == 1 ? " thread" : " threads") + ", one shared generator"};
}
