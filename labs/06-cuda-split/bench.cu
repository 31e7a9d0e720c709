// lab06-bench: the wavefront benchmark (bench/gpu/wavefront_bench.cuh) on lab 06's
// path pool, the array of structures, next to lab 05's reference megakernel.
#include <bench_main.h>
#include <path_pool_aos.cuh>
#include <wavefront_bench.cuh>

// Lab 06's bar: its reference on the baseline, on an H200.
constexpr SpeedTarget kLab06Targets[] = {{"AoS", 60.0, nullptr}};

static int run(int argc, char** argv) {
    return run_wavefront_bench<AosPathPool>(argc, argv, kLab06Targets);
}

int main(int argc, char** argv) { return bench_main(run, argc, argv); }
