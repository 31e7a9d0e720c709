// The entry of lab03-simd-ref, built without SIMD flags: it checks the CPU, then calls the
// render() of solution/render.cpp, which is built with -DRT_USE_SIMD and common/simd/ first on
// the include path and renamed render_avx2 there. Its PixelRenderer renders each pixel with
// the widest packets this CPU runs (common/simd/packet_renderer.h), which the run's summary
// names. So a CPU without AVX2 gets one clear line instead of an illegal instruction
// (common/host/cpu_features.h), and one without AVX-512 runs the 8-lane code.
#include "cpu_features.h"
#include "lab.h"
#include "packet_renderer.h"

RenderStats render_avx2(const RenderJob& job, Image& image);

RenderStats render(const RenderJob& job, Image& image) {
    require_avx2("lab03-simd-ref (OpenMP on lab 02's SIMD packets)", cpu_model_name());
    RenderStats stats = render_avx2(job, image);
    stats.device += ", " + widest_packet_renderer().describe();
    return stats;
}
