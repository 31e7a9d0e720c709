// Renders one pixel of a job: what the parallel labs (03-openmp, 04-mpi) distribute.
// Built with -DRT_USE_SIMD it renders with lab 02's AVX2 geometry instead, which is how the
// "SIMD" variants of those labs are made from the same source.
#pragma once

#include "lab.h"
#include "path_tracer.h"

// Scalar pixels: exactly lab 01's render_pixel, so any schedule gives lab 01's image, bit for
// bit.
class ScalarPixelRenderer {
public:
    explicit ScalarPixelRenderer(const RenderJob& job)
        : scene_(job.scene.view()), camera_(job.camera), settings_(job.settings) {}

    Vec3 operator()(int x, int y) const { return render_pixel(scene_, camera_, settings_, x, y); }

    static const char* name() { return "scalar"; }

private:
    SceneView scene_;
    Camera camera_;
    RenderSettings settings_;
};

#if defined(RT_USE_SIMD)
#include "simd_pixel_renderer.h"  // SimdPixelRenderer, from lab 02
using PixelRenderer = SimdPixelRenderer;
#else
using PixelRenderer = ScalarPixelRenderer;
#endif
