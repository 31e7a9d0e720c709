// Run-time CPU feature detection for lab 02's SIMD code (and the SIMD variants of later labs).
//
// Call require_avx2() from a translation unit built WITHOUT -mavx2, before any AVX2 code
// runs: a file built with -mavx2 may use AVX instructions anywhere, even in the check.
// Likewise cpu_has_avx512() decides, in code built without AVX-512, whether the 16-lane
// objects may run. Setting RT_FORCE_NO_AVX2=1 makes the AVX2 check fail on any CPU, to test
// the message; RT_FORCE_NO_AVX512=1 makes the references take their AVX2 path, to test it
// on an AVX-512 machine.
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
// Whether environment variable `name` is set to anything but "" or "0".
inline bool forced_off(const char* name) {
    const char* force = std::getenv(name);
    return force != nullptr && *force != '\0' && std::strcmp(force, "0") != 0;
}

inline bool cpu_has_avx2() {
    if (forced_off("RT_FORCE_NO_AVX2")) return false;
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

// Whether this CPU runs the 16-lane code (simd16.h: AVX-512 F, DQ, VL and BW; Intel Skylake-SP,
// 2017, and AMD Zen 4, 2022, onwards) besides AVX2, and RT_FORCE_NO_AVX512 is unset or "0".
inline bool cpu_has_avx512() {
    if (!cpu_has_avx2() || forced_off("RT_FORCE_NO_AVX512")) return false;
#if defined(__x86_64__) || defined(__i386__)
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512bw");
#else
    return false;
#endif
}
