// Compiles the shared renderer's host+device code for the GPU: every RT_HD function a CUDA
// lab will call must build under nvcc. Built by `make check-nvcc`; nothing here runs.
#include <path_tracer.h>

__global__ void render_kernel(SceneView scene, Camera camera, RenderSettings settings,
                              Vec3* pixels) {
    const int x = blockIdx.x * blockDim.x + threadIdx.x;
    const int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= settings.width || y >= settings.height) return;
    pixels[y * settings.width + x] = render_pixel(scene, camera, settings, x, y);
}

int main() { return 0; }
