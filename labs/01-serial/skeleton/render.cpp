// Lab 01: your copy, yours to edit. Every place to fill in is marked TODO(lab01).
// Lab 01: the serial renderer, the baseline every speedup in this course is measured against.
// The loop nest of Algorithm 1: pixels here; samples in render_pixel, bounces in trace_path,
// primitives in closest_hit (all in path_tracer.h).
#include "lab.h"
#include "path_tracer.h"
#include "timer.h"

const char* const kLabName = "01-serial";

RenderStats render(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    const Timer timer;
    // TODO(lab01): render every pixel of the image. Until then: only the left half.
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width / 2; ++x) {
            image.at(x, y) = render_pixel(scene, job.camera, settings, x, y);
        }
        job.progress.rows_done();
    }
    return {timer.seconds(), cpu_model_name() + ", 1 thread"};
}
