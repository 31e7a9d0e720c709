// One macro marks code that runs on both host and device (pbrt-v4's PBRT_CPU_GPU idea).
// Under nvcc it expands to __host__ __device__; under g++ it vanishes.
#pragma once

#if defined(__CUDACC__)
#define RT_HD __host__ __device__
#else
#define RT_HD
#endif
