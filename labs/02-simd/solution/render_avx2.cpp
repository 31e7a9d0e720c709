// Lab 02 Part B: lab 01's pixel loop over the packet tracer: each pixel's samples go 8 at a
// time, one path per AVX2 lane. Built with -mavx2 -mfma (labs/02-simd/lab.mk); render.cpp
// checks the CPU first.
#include "lab.h"
#include "packet_tracer.h"
#include "timer.h"

RenderStats render_avx2(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    const Timer timer;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            image.at(x, y) = render_pixel_packets(scene, job.camera, settings, x, y);
        }
        job.progress.rows_done();
    }
    return {timer.seconds(), cpu_model_name() + ", 1 thread, AVX2, 8 paths per packet"};
}
