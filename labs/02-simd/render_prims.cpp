// Lab 02, a worked example for comparison (./lab02-prims): SIMD across primitives. Lab 01's
// pixel loop and path loop, with closest_hit / occluded testing one ray against 8 primitives
// per instruction (simd_geometry.h). Building the packets is part of the work, so it is
// timed (microseconds). Built with -mavx2 -mfma; render.cpp checks the CPU first.
#include "lab.h"
#include "simd_geometry.h"
#include "timer.h"

RenderStats render_avx2(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    const Timer timer;
    const SimdScene packets(scene);  // the SoA copy
    const SimdSceneView geometry = packets.view();
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            image.at(x, y) = render_pixel(scene, geometry, job.camera, settings, x, y);
        }
        job.progress.rows_done();
    }
    return {timer.seconds(), cpu_model_name() + ", 1 thread, AVX2, 8 primitives per test"};
}
