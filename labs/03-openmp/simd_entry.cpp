// The entry of lab03-simd-ref, built without AVX2: it checks the CPU, then calls the render()
// of solution/render.cpp, which is built with -DRT_USE_SIMD -mavx2 -mfma and renamed
// render_avx2 there. So a CPU without AVX2 gets one clear line instead of an illegal
// instruction (common/host/cpu_features.h).
#include "cpu_features.h"
#include "lab.h"

RenderStats render_avx2(const RenderJob& job, Image& image);

RenderStats render(const RenderJob& job, Image& image) {
    require_avx2("lab03-simd-ref (OpenMP on lab 02's AVX2 geometry)", cpu_model_name());
    return render_avx2(job, image);
}
