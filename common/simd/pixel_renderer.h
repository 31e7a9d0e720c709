// Lab 02's packet tracer as the renderer of one pixel: it stands in for
// common/host/pixel_renderer.h (same name, same interface) in the builds that put common/simd/
// first on the include path, the "SIMD" variants of labs 03 and 04. Each pixel's samples go
// through the widest packets this CPU runs, compacted (packet_renderer.h): 16 AVX-512 lanes
// where the CPU has them, else 8 AVX2 lanes; the image is lab 01's, bit for bit.
//
// No intrinsics here: the SIMD code lives in the library's objects (SIMD_OBJ in Makefile),
// reached through a function pointer chosen at run time. Construct it only once
// require_avx2() (cpu_features.h) has passed, as the labs' simd_entry.cpp does.
#pragma once

#include <lab.h>
#include <packet_renderer.h>

class PixelRenderer {
public:
    explicit PixelRenderer(const RenderJob& job)
        : scene_(job.scene),
          camera_(job.camera),
          settings_(job.settings),
          packets_(widest_packet_renderer()) {}

    // Reads only: safe to call from any number of threads at once.
    Vec3 operator()(int x, int y) const {
        Vec3 mean;
        packets_.render(scene_, camera_, settings_, static_cast<long>(y) * settings_.width + x, 1,
                        &mean);
        return mean;
    }

    static const char* name() { return "SIMD"; }

private:
    // All by value and small; the packet tracer reads the scene's arrays as loaded.
    SceneView scene_;
    Camera camera_;
    RenderSettings settings_;
    PacketRenderer packets_;  // the width chosen for this CPU
};
