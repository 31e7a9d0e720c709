// lab07-bench: the wavefront benchmark (bench/gpu/wavefront_bench.cuh) on both path
// pools, lab 06's array of structures and lab 07's structure of arrays, in the same run on
// the same scene, next to lab 05's reference megakernel.
#include <bench_main.h>
#include <path_pool_aos.cuh>
#include <path_pool_soa.cuh>
#include <wavefront_bench.cuh>

// Lab 07's bar: the structure of arrays faster than lab 06's pool (which keeps its own bar).
constexpr SpeedTarget kLab07Targets[] = {{"AoS", 60.0, nullptr}, {"SoA", 0.0, "AoS"}};

static int run(int argc, char** argv) {
    return run_wavefront_bench<AosPathPool, SoaPathPool>(argc, argv, kLab07Targets);
}

int main(int argc, char** argv) { return bench_main(run, argc, argv); }
