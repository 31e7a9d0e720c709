// Lab 02's renderer of one pixel: the packet tracer (packet_tracer.h), 8 samples per AVX2
// packet. It stands in for common/host/pixel_renderer.h (same name, same interface) in the
// builds that put common/simd/ first on the include path: the "SIMD" variants of labs 03
// and 04.
//
// Include it only in a translation unit built with -mavx2 -mfma, and call require_avx2()
// (cpu_features.h) from one built without, before any AVX2 code runs.
#pragma once

#include <lab.h>
#include <packet_tracer.h>

class PixelRenderer {
public:
    explicit PixelRenderer(const RenderJob& job)
        : scene_(job.scene), camera_(job.camera), settings_(job.settings) {}

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
