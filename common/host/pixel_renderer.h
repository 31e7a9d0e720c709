// Renders one pixel of a job: what the parallel labs (03-openmp, 04-mpi) distribute.
// This is the scalar one, exactly lab 01's render_pixel, so any schedule gives lab 01's image
// bit for bit. Their "SIMD" variants put common/simd/ first on the include path, where
// pixel_renderer.h renders with lab 02's AVX2 packet tracer instead: same source, other
// include path.
#pragma once

#include <lab.h>
#include <path_tracer.h>

class PixelRenderer {
public:
    explicit PixelRenderer(const RenderJob& job)
        : scene_(job.scene), camera_(job.camera), settings_(job.settings) {}

    // Reads only: safe to call from any number of threads at once.
    Vec3 operator()(int x, int y) const { return render_pixel(scene_, camera_, settings_, x, y); }

    static const char* name() { return "scalar"; }

private:
    SceneView scene_;
    Camera camera_;
    RenderSettings settings_;
};
