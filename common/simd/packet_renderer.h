// The packet tracer at the width this CPU has, chosen at run time: which object of the SIMD
// library renders (labs 02-04's references, `make render`). Plain declarations, no
// intrinsics: this header is for code built WITHOUT AVX2 or AVX-512, which checks the CPU
// (cpu_features.h) and then calls into the objects built with them:
//
//   packets_avx2.cpp    (-mavx2 -mfma)        simd8.h:  8 lanes, packet_tracer.h and compacted
//   packets_avx512.cpp  (SIMD_AVX512_FLAGS)   simd16.h: 16 lanes, the same two templates
//   packet_renderer.cpp (no SIMD flags)       the choice
//
// A binary links all three and runs on any CPU with AVX2: the 16-lane code only runs where
// cpu_has_avx512() said yes.
#pragma once

#include <string>

#include <camera.h>
#include <lane_use.h>
#include <scene_view.h>

// Renders pixel_count consecutive pixels from pixel index first_pixel (y * width + x) into
// out[0 .. pixel_count - 1]: render_pixel's image, bit for bit.
using RenderPixels = void (*)(const SceneView& scene, const Camera& camera,
                              const RenderSettings& settings, long first_pixel, int pixel_count,
                              Vec3* out);

// Traces the same paths as RenderPixels, tallying each bounce's packets and paths in `use`.
using CountLanes = void (*)(const SceneView& scene, const Camera& camera,
                            const RenderSettings& settings, long first_pixel, int pixel_count,
                            bool compacted, LaneUse& use);

// One way of rendering with packets.
struct PacketRenderer {
    RenderPixels render;  // the function
    CountLanes count;     // its lane use, measured (lab02-bench)
    int lanes;            // paths per packet: 8 (AVX2) or 16 (AVX-512)
    bool compacted;       // survivors repacked after every bounce (compacted_tracer.h)

    // "AVX-512, 16 paths per packet, compacted": for the run's summary and --json.
    std::string describe() const;
};

// The references' choice: the widest packets this CPU runs, compacted. Call it only once
// require_avx2() (cpu_features.h) has passed.
PacketRenderer widest_packet_renderer();

// A given width and method, for measurements (lab02-bench). Throws MissingCpuFeature when the
// CPU lacks what `lanes` needs, InputError for a width other than 8 or 16.
PacketRenderer packet_renderer(int lanes, bool compacted);
