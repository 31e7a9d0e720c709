// Lab 02: your copy, yours to edit. Every place to fill in is marked TODO(lab02).
// Lab 02 Part B: the serial renderer, 8 paths per AVX2 packet. This file checks the CPU and
// is built for any x86-64; the AVX2 code is in render_avx2.cpp, built with -mavx2 -mfma, so
// that a CPU without AVX2 gets a clear message here instead of an illegal-instruction crash
// there.
#include "cpu_features.h"
#include "lab.h"

const char* const kLabName = "02-simd";

// The AVX2 pixel loop (render_avx2.cpp; render_prims.cpp in ./lab02-prims).
RenderStats render_avx2(const RenderJob& job, Image& image);

RenderStats render(const RenderJob& job, Image& image) {
    require_avx2("lab 02 (AVX2, 8 lanes)", cpu_model_name());
    return render_avx2(job, image);
}
