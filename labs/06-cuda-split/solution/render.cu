// Lab 06: the path tracer as a wavefront of small kernels connected by queues of paths
// (wavefront_kernels.cuh), the paths kept in a pool in device memory as an array of
// structures (path_pool_aos.cuh). What students write: the queue's reserve (queue_reserve.cuh)
// and the stage loop (stage_loop.cuh). Lab 07 runs the same kernels on a structure of
// arrays.
#include <path_pool_aos.cuh>
#include <wavefront_renderer.cuh>

const char* const kLabName = "06-cuda-split";

RenderStats render(const RenderJob& job, Image& image) {
    return render_wavefront<AosPathPool>(job, image);
}
