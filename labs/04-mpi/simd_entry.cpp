// The entry of lab04-simd-ref, built without SIMD flags: the ranks check their CPUs and agree,
// then run render() of solution/render.cpp, which is built with -DRT_USE_SIMD and common/simd/
// first on the include path and renamed render_avx2 there. A host without AVX2 thus stops
// every rank with one clear line instead of an illegal instruction on that host and a hang on
// the others. Each rank renders with the widest packets its own CPU runs (the same bits at
// any width, so hosts may differ); the summary names rank 0's.
#include <mpi.h>

#include "cpu_features.h"
#include "lab.h"
#include "packet_renderer.h"

RenderStats render_avx2(const RenderJob& job, Image& image);

RenderStats render(const RenderJob& job, Image& image) {
    int all_have_avx2 = cpu_has_avx2();
    MPI_Allreduce(MPI_IN_PLACE, &all_have_avx2, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    if (!all_have_avx2) {
        require_avx2("lab04-simd-ref (MPI on lab 02's SIMD packets)", cpu_model_name());
        throw MissingCpuFeature(
            "lab04-simd-ref needs AVX2 and FMA on every host, and another "
            "MPI rank's CPU has not");
    }
    RenderStats stats = render_avx2(job, image);
    stats.device += ", " + widest_packet_renderer().describe() + " (rank 0)";
    return stats;
}
