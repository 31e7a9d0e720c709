// Run-time CPU feature detection for lab 02's AVX2 code (and the SIMD variants of later labs).
//
// Call require_avx2() from a translation unit built WITHOUT -mavx2, before any AVX2 code
// runs: a file built with -mavx2 may use AVX instructions anywhere, even in the check.
// Setting RT_FORCE_NO_AVX2=1 makes the check fail on any CPU, to test the message.
#pragma once

#include <cstdlib>
#include <cstring>
#include <string>

#include <errors.h>

// Thrown when the CPU cannot run a lab's code. The shared main prints it as one line,
// removes any half-written output and exits with status 2, as for bad input.
struct MissingCpuFeature : InputError {
    using InputError::InputError;
};

// Whether this CPU runs AVX2 and FMA (Intel Haswell, 2013, and AMD Excavator/Zen onwards),
// and RT_FORCE_NO_AVX2 is unset or "0".
inline bool cpu_has_avx2() {
    const char* force = std::getenv("RT_FORCE_NO_AVX2");
    if (force != nullptr && *force != '\0' && std::strcmp(force, "0") != 0) return false;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
#else
    return false;
#endif
}

// Throws MissingCpuFeature naming `what` and the CPU when cpu_has_avx2() is false.
inline void require_avx2(const char* what, const std::string& cpu_name) {
    if (cpu_has_avx2()) return;
    const char* force = std::getenv("RT_FORCE_NO_AVX2");
    throw MissingCpuFeature(
        std::string(what) + " needs a CPU with AVX2 and FMA, and this one (" + cpu_name +
        ") has not" + (force != nullptr && *force != '\0' ? " (RT_FORCE_NO_AVX2 is set)" : "") +
        ": run it on an x86-64 CPU from 2013 or later (Intel Haswell, AMD Zen), or use the "
        "scalar lab 01");
}
