// Lab 07: lab 06's wavefront renderer, its kernels unchanged, on a path pool laid out as a
// structure of arrays (path_pool_soa.cuh) instead of an array of structures.
#include <path_pool_soa.cuh>
#include <wavefront_renderer.cuh>

const char* const kLabName = "07-soa";

RenderStats render(const RenderJob& job, Image& image) {
    return render_wavefront<SoaPathPool>(job, image);
}
