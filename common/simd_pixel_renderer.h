// Lab 02's renderer of one pixel: the packet tracer (packet_tracer.h), 8 samples per AVX2
// packet. common/pixel_renderer.h makes it the PixelRenderer when built with -DRT_USE_SIMD,
// which is how labs 03 and 04 get their "SIMD" variants from the same source.
//
// Include it only in a translation unit built with -mavx2 -mfma, and call require_avx2()
// (cpu_features.h) from one built without, before any AVX2 code runs.
#pragma once

#include "lab.h"
#include "packet_tracer.h"

class SimdPixelRenderer {
public:
    explicit SimdPixelRenderer(const RenderJob& job)
        : scene_(job.scene.view()), camera_(job.camera), settings_(job.settings) {}

    // Reads only: safe to call from any number of threads at once.
    Vec3 operator()(int x, int y) const {
        return render_pixel_packets(scene_, camera_, settings_, x, y);
    }

    static const char* name() { return "SIMD"; }

private:
    // All by value and small; the packet tracer reads the scene's arrays as loaded.
    SceneView scene_;
    Camera camera_;
    RenderSettings settings_;
};
