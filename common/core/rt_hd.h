// One macro marks code that runs on both host and device (pbrt-v4's PBRT_CPU_GPU idea).
// Under nvcc it expands to __host__ __device__; under g++ it vanishes.
#pragma once

#if defined(__CUDACC__)
#define RT_HD __host__ __device__
#else
#define RT_HD
#endif

// Inlined wherever it is called, whatever the compiler's estimate of the cost: for functions
// whose callers' constants or registers are what make them cheap.
#if defined(__CUDACC__)
#define RT_FORCE_INLINE __forceinline__
#else
#define RT_FORCE_INLINE inline __attribute__((always_inline))
#endif

// How a primitive test ends when a cheap test already rejects the primitive. A CPU core
// returns at once and skips the arithmetic that the rejection made needless. A GPU warp
// would run that arithmetic anyway for any of its lanes that still needs it, and an early
// return only splits the warp (its lanes then run the rest of the loop apart and must be
// joined again): there the rejection joins the select that chooses the answer at the end,
// and the warp skips the rest of the test only when the cheap test rejects the primitive on
// every one of its lanes (any_lane, below), a branch all its lanes take together. Each test takes the form as a template
// argument that defaults to the machine's, so that a CPU can run the GPU's form too: the unit
// tests check that both return the same bits (tests/unit/test_converged_tests.cpp).
#if defined(__CUDA_ARCH__)
constexpr bool kConvergedTests = true;
#else
constexpr bool kConvergedTests = false;
#endif

// Whether `condition` holds on any lane of the warp that runs this code together: on a GPU
// every lane gets the same answer, so a branch on it keeps the warp together (all its lanes
// take it, or none); elsewhere a thread is its own warp. For a converged test that can skip
// its arithmetic when every lane has already rejected the primitive.
RT_HD inline bool any_lane(bool condition) {
#if defined(__CUDA_ARCH__)
    return __any_sync(__activemask(), condition);
#else
    return condition;
#endif
}
