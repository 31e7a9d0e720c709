// Lab 02 Part A: lab 01's renderer, unchanged, compiled with the SSE Vec3 of lab 02's vec3.h
// (every file of ./lab02a and ./lab02a-ref is built with it first on the include path, so the
// whole program agrees on Vec3's layout). SSE2 is part of every x86-64 CPU: no run-time check
// needed. kVec3Kind exists only in lab 02's vec3.h: built against the scalar one, this file
// does not compile.
#include "lab.h"
#include "path_tracer.h"
#include "timer.h"

const char* const kLabName = "02-simd-a";

RenderStats render(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    const Timer timer;
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            image.at(x, y) = render_pixel(scene, job.camera, settings, x, y);
        }
        job.progress.rows_done();
    }
    return {timer.seconds(), cpu_model_name() + ", 1 thread, " + kVec3Kind};
}
