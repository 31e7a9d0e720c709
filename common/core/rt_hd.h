// One macro marks code that runs on both host and device (pbrt-v4's PBRT_CPU_GPU idea).
// Under nvcc it expands to __host__ __device__; under g++ it vanishes.
#pragma once

#if defined(__CUDACC__)
#define RT_HD __host__ __device__
#else
#define RT_HD
#endif

// How a primitive test ends when a cheap test already rejects the primitive. A CPU core
// returns at once and skips the arithmetic that the rejection made needless. A GPU warp
// would run that arithmetic anyway for any of its lanes that still needs it, and an early
// return only splits the warp (its lanes then run the rest of the loop apart and must be
// joined again): there every lane runs every instruction of the test, and the rejection
// joins the select that chooses the answer at the end. Each test takes the form as a template
// argument that defaults to the machine's, so that a CPU can run the GPU's form too: the unit
// tests check that both return the same bits (tests/unit/test_converged_tests.cpp).
#if defined(__CUDA_ARCH__)
constexpr bool kConvergedTests = true;
#else
constexpr bool kConvergedTests = false;
#endif
