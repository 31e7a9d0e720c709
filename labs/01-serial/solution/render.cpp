// Lab 01: the serial renderer, the baseline every speedup in this course is measured against.
// The loop nest of Algorithm 1: pixels here; samples in render_pixel, bounces in trace_path,
// primitives in closest_hit (render_pixel and closest_hit in path_steps.h, what you write;
// trace_path in path_tracer.h).
#include "lab.h"
#include "path_tracer.h"
#include "timer.h"

const char* const kLabName = "01-serial";

// Every pixel of the image, with the material kinds `Materials` compiled in (material_set.h).
template <class Materials>
static void render_rows(const RenderJob& job, Image& image) {
    const SceneView scene = job.scene;
    const RenderSettings& settings = job.settings;
    // BEGIN SOLUTION
    for (int y = 0; y < settings.height; ++y) {
        for (int x = 0; x < settings.width; ++x) {
            image.at(x, y) = render_pixel<Materials>(scene, job.camera, settings, x, y);
        }
        job.progress.rows_done();
    }
    // SKELETON
    //> // TODO(lab01): render every pixel of the image. Until then: only the left half.
    //> for (int y = 0; y < settings.height; ++y) {
    //>     for (int x = 0; x < settings.width / 2; ++x) {
    //>         image.at(x, y) = render_pixel<Materials>(scene, job.camera, settings, x, y);
    //>     }
    //>     job.progress.rows_done();
    //> }
    // END SOLUTION
}

// A scene without mirrors or glass gets the loop compiled without their code (DiffuseOnly);
// the arithmetic of a diffuse hit is the same either way, so is the image.
RenderStats render(const RenderJob& job, Image& image) {
    const Timer timer;
    if (has_specular_material(job.scene.materials, job.scene.num_materials)) {
        render_rows<AnyMaterial>(job, image);
    } else {
        render_rows<DiffuseOnly>(job, image);
    }
    return {timer.seconds(), cpu_model_name() + ", 1 thread"};
}
